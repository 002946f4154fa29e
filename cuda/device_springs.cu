// SPDX-License-Identifier: MIT
#include "device_springs.h"
#include "kernel_launch.h"

namespace sph {
namespace {

__global__ void spring_inverse_kernel(const uint32_t* __restrict__ order, uint32_t n, uint32_t* inverse) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) inverse[order[i]] = i;
}

__global__ void spring_reorder_kernel(const SpringList* __restrict__ springs,
                                      const uint32_t* __restrict__ order,
                                      const uint32_t* __restrict__ inverse,
                                      const uint32_t* __restrict__ ghost, uint32_t n, SpringList* sorted) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  sorted[i] = ghost && ghost[i] ? springs[order[i]] : remap_spring_list(springs[order[i]], inverse);
}

__global__ void spring_candidates_kernel(SpringConstants c, GridView grid, ParticleArrays a, uint32_t n) {
  const uint32_t from = *a.link_from;
  if (from == kNoPendingLinks) return;  // nobody waits: the usual case, one load per thread
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  if (a.halo_ghost && a.halo_ghost[i]) {  // (a ghost's come from its owner)
    for (uint32_t k = 0; k < kSpringSlots; ++k)
      a.spring_candidates[static_cast<uint64_t>(i) * kSpringSlots + k] = kNoSpring;
    return;
  }
  spring_candidates(c, grid, a.sorted_position, a.sorted_id, from, a.sorted_springs[i], i,
                    a.spring_candidates + static_cast<uint64_t>(i) * kSpringSlots);
}

__global__ void spring_link_kernel(ParticleArrays a, uint32_t n) {
  if (*a.link_from == kNoPendingLinks) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || (a.halo_ghost && a.halo_ghost[i])) return;
  SpringList own = a.sorted_springs[i];
  spring_link(a.sorted_position, a.spring_candidates, i, own);
  a.sorted_springs[i] = own;
}

template <bool kUpdateRest>
__global__ void spring_force_kernel(SpringConstants c, ParticleArrays a, uint32_t n,
                                    const FrameState* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  SpringList own = a.sorted_springs[i];
  if (a.halo_ghost && a.halo_ghost[i]) {  // (its owner's to compute)
    a.spring_acceleration[i] = make_float4_record(Vec3{0.0f, 0.0f, 0.0f}, 0.0f);
    a.springs[i] = own;
    return;
  }
  const Vec3 acc = spring_acceleration<kUpdateRest>(c, a.sorted_position, a.sorted_velocity, i, own,
                                                    state->clock.dt_float);
  a.spring_acceleration[i] = make_float4_record(acc, 0.0f);
  a.springs[i] = own;
}

__global__ void spring_compact_index_kernel(const uint32_t* __restrict__ keep,
                                            const uint32_t* __restrict__ scan, uint32_t n,
                                            uint32_t* inverse) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) inverse[i] = keep[i] ? scan[i] : kNoSpring;
}

__global__ void spring_compact_kernel(const SpringList* __restrict__ springs,
                                      const uint32_t* __restrict__ keep, const uint32_t* __restrict__ scan,
                                      const uint32_t* __restrict__ inverse, uint32_t n, SpringList* out) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n && keep[i]) out[scan[i]] = inverse ? remap_spring_list(springs[i], inverse) : springs[i];
}

__global__ void springs_appended_kernel(uint32_t* link_from, uint32_t first_id) {
  if (first_id < *link_from) *link_from = first_id;
}

}  // namespace

std::vector<ParticleArraySpec> spring_device_arrays() {
  return {ParticleArraySpec{kArraySortedSprings, sizeof(SpringList), ParticleArrayRole::Scratch, 1, nullptr,
                            nullptr},
          ParticleArraySpec{kArraySpringInverse, sizeof(uint32_t), ParticleArrayRole::Scratch, 1, nullptr,
                            nullptr}};
}

void enqueue_spring_reorder(const ParticleArrays& a, const uint32_t* order, uint32_t n, cudaStream_t stream) {
  const unsigned blocks = blocks_for(n, kDefaultBlockSize);
  spring_inverse_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(order, n, a.spring_inverse);
  check_launch("spring_inverse_kernel");
  spring_reorder_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(a.springs, order, a.spring_inverse,
                                                                  a.halo_ghost, n, a.sorted_springs);
  check_launch("spring_reorder_kernel");
}

void enqueue_spring_pass(const SpringConstants& c, const GridView& grid, const ParticleArrays& a, uint32_t n,
                         bool update_rest, FrameState* state, cudaStream_t stream, SpringRankStep* rank) {
  constexpr unsigned kThreads = 128;
  const unsigned blocks = blocks_for(n, kThreads);
  spring_candidates_kernel<<<blocks, kThreads, 0, stream>>>(c, grid, a, n);
  check_launch("spring_candidates_kernel");
  if (rank) rank->between_link_passes(stream);
  spring_link_kernel<<<blocks, kThreads, 0, stream>>>(a, n);
  check_launch("spring_link_kernel");
  cuda_check(cudaMemsetAsync(a.link_from, 0xff, sizeof(uint32_t), stream), "spring link state clear");
  if (update_rest)
    spring_force_kernel<true><<<blocks, kThreads, 0, stream>>>(c, a, n, state);
  else
    spring_force_kernel<false><<<blocks, kThreads, 0, stream>>>(c, a, n, state);
  check_launch("spring_force_kernel");
}

void enqueue_spring_compact(const ParticleArrays& a, uint32_t n, uint32_t kept, const uint32_t* keep,
                            const uint32_t* scan, bool partner_ids, cudaStream_t stream) {
  const unsigned blocks = blocks_for(n, kDefaultBlockSize);
  if (!partner_ids) {
    spring_compact_index_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(keep, scan, n, a.spring_inverse);
    check_launch("spring_compact_index_kernel");
  }
  spring_compact_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(
      a.springs, keep, scan, partner_ids ? nullptr : a.spring_inverse, n, a.sorted_springs);
  check_launch("spring_compact_kernel");
  if (kept > 0)
    cuda_check(cudaMemcpyAsync(a.springs, a.sorted_springs, sizeof(SpringList) * kept,
                               cudaMemcpyDeviceToDevice, stream),
               "compaction of spring lists");
}

void enqueue_springs_appended(const ParticleArrays& a, uint32_t first_id, cudaStream_t stream) {
  springs_appended_kernel<<<1, 1, 0, stream>>>(a.link_from, first_id);
  check_launch("springs_appended_kernel");
}

}  // namespace sph
