#include <cfloat>

#include "../src/physics/density.h"
#include "frame_statistics.h"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr unsigned kStatsBlock = 256;

__device__ void combine(StatsPartial& a, const StatsPartial& b) {
  a.density_sum += b.density_sum;
  a.neighbor_sum += b.neighbor_sum;
  a.density_min = fminf(a.density_min, b.density_min);
  a.density_max = fmaxf(a.density_max, b.density_max);
  a.neighbor_max = max(a.neighbor_max, b.neighbor_max);
}

__device__ StatsPartial empty_partial() { return StatsPartial{0.0, 0ull, FLT_MAX, -FLT_MAX, 0u, 0u}; }

// Fixed-shape tree over the block's shared slots: the same additions in the same order on
// every run.
__device__ void tree_reduce(StatsPartial* slots) {
  for (unsigned stride = kStatsBlock / 2; stride > 0; stride >>= 1) {
    __syncthreads();
    if (threadIdx.x < stride) combine(slots[threadIdx.x], slots[threadIdx.x + stride]);
  }
  __syncthreads();
}

__global__ void __launch_bounds__(kStatsBlock)
    stats_partial_kernel(FluidConstants fluid, GridView grid, const Float4* sorted_position,
                         const float* __restrict__ density, const uint32_t* __restrict__ counts, uint32_t n,
                         StatsPartial* partials, FrameState* state) {
  mark_stage(state, kStageOther);
  __shared__ StatsPartial slots[kStatsBlock];
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  StatsPartial p = empty_partial();
  if (i < n) {
    const float d = density[i];
    const uint32_t neighbors =
        counts ? counts[i] : gather_density(fluid, grid, sorted_position, i).neighbor_count;
    p = StatsPartial{d, neighbors, d, d, neighbors, 0u};
  }
  slots[threadIdx.x] = p;
  tree_reduce(slots);
  if (threadIdx.x == 0) partials[blockIdx.x] = slots[0];
}

__global__ void __launch_bounds__(kStatsBlock)
    stats_final_kernel(const StatsPartial* partials, uint32_t blocks, uint32_t n, FrameState* state) {
  __shared__ StatsPartial slots[kStatsBlock];
  StatsPartial p = empty_partial();
  for (uint32_t b = threadIdx.x; b < blocks; b += kStatsBlock) combine(p, partials[b]);
  slots[threadIdx.x] = p;
  tree_reduce(slots);
  if (threadIdx.x == 0) {
    const StatsPartial& t = slots[0];
    const bool any = n > 0;
    state->density_min = any ? t.density_min : 0.0f;
    state->density_max = any ? t.density_max : 0.0f;
    state->density_mean = any ? static_cast<float>(t.density_sum / n) : 0.0f;
    state->neighbors_mean = any ? static_cast<float>(static_cast<double>(t.neighbor_sum) / n) : 0.0f;
    state->neighbors_max = any ? t.neighbor_max : 0u;
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
                              uint32_t n, FrameState* state, cudaStream_t stream,
                              const uint32_t* counts) const {
  const unsigned blocks = blocks_for(n, kStatsBlock);
  stats_partial_kernel<<<blocks, kStatsBlock, 0, stream>>>(fluid, grid, a.sorted_position, a.density, counts,
                                                           n, partials_.get(), state);
  check_launch("stats_partial_kernel");
  stats_final_kernel<<<1, kStatsBlock, 0, stream>>>(partials_.get(), blocks, n, state);
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
