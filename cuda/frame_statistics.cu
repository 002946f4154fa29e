// SPDX-License-Identifier: MIT
#include "../src/physics/density.h"
#include "frame_statistics.h"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr unsigned kStatsBlock = 256;

// Fixed-shape tree over the block's shared slots: the same additions in the same order on
// every run.
__device__ void tree_reduce(DensityTally* slots) {
  for (unsigned stride = kStatsBlock / 2; stride > 0; stride >>= 1) {
    __syncthreads();
    if (threadIdx.x < stride) combine(slots[threadIdx.x], slots[threadIdx.x + stride]);
  }
  __syncthreads();
}

__global__ void __launch_bounds__(kStatsBlock)
    stats_partial_kernel(FluidConstants fluid, GridView grid, const Float4* sorted_position,
                         const float* __restrict__ density, const uint32_t* __restrict__ counts,
                         const uint32_t* __restrict__ ghost, uint32_t n, DensityTally* partials,
                         FrameState* state) {
  mark_stage(state, kStageOther);
  __shared__ DensityTally slots[kStatsBlock];
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  DensityTally p = empty_tally();
  if (i < n && !(ghost && ghost[i])) {
    const float d = density[i];
    const uint32_t neighbors =
        counts ? counts[i] : gather_density(fluid, grid, sorted_position, i).neighbor_count;
    p = particle_tally(d, neighbors);
  }
  slots[threadIdx.x] = p;
  tree_reduce(slots);
  if (threadIdx.x == 0) partials[blockIdx.x] = slots[0];
}

__global__ void __launch_bounds__(kStatsBlock)
    stats_final_kernel(const DensityTally* partials, uint32_t blocks, uint32_t n, FrameState* state) {
  __shared__ DensityTally slots[kStatsBlock];
  DensityTally p = empty_tally();
  for (uint32_t b = threadIdx.x; b < blocks; b += kStatsBlock) combine(p, partials[b]);
  slots[threadIdx.x] = p;
  tree_reduce(slots);
  if (threadIdx.x == 0) {
    state->density = finish_record(slots[0], n);
    mark_stage(state, kStageOther);
  }
}

__global__ void neighbor_count_kernel(FluidConstants fluid, GridView grid, const Float4* sorted_position,
                                      uint32_t n, uint32_t* counts) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) counts[i] = gather_density(fluid, grid, sorted_position, i).neighbor_count;
}

}  // namespace

FrameStatistics::FrameStatistics(uint32_t capacity) {
  partials_.allocate(blocks_for(capacity, kStatsBlock), "statistics partials");
}

void FrameStatistics::enqueue(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                              uint32_t n, FrameState* state, cudaStream_t stream, const uint32_t* counts,
                              uint32_t ghosts) const {
  const unsigned blocks = blocks_for(n, kStatsBlock);
  stats_partial_kernel<<<blocks, kStatsBlock, 0, stream>>>(fluid, grid, a.sorted_position, a.density, counts,
                                                           ghosts ? a.halo_ghost : nullptr, n,
                                                           partials_.get(), state);
  check_launch("stats_partial_kernel");
  stats_final_kernel<<<1, kStatsBlock, 0, stream>>>(partials_.get(), blocks, n - ghosts, state);
  check_launch("stats_final_kernel");
}

void FrameStatistics::enqueue_neighbor_counts(const FluidConstants& fluid, const GridView& grid,
                                              const ParticleArrays& a, uint32_t n, uint32_t* counts,
                                              cudaStream_t stream) const {
  neighbor_count_kernel<<<blocks_for(n, kStatsBlock), kStatsBlock, 0, stream>>>(fluid, grid,
                                                                                a.sorted_position, n, counts);
  check_launch("neighbor_count_kernel");
}

}  // namespace sph
