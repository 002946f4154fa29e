// SPDX-License-Identifier: MIT
// DFSPH's neighbour lists (physics/neighbor_walk.h, docs/cuda.md): written once a substep from the
// density pass's candidate masks, read by the solves' passes (ListedCandidates).
#include "dfsph_solver.h"
#include "kernel_launch.h"

namespace sph {
namespace {

// Particle i's neighbour list from its mask, after the density pass wrote the masks and before
// the solves read either.
__global__ void dfsph_list_kernel(GridView grid, ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  write_neighbor_list(grid, xyz(a.sorted_position[i]),
                      a.dfsph_neighbor_mask + static_cast<size_t>(i) * kNeighborMaskWords,
                      a.dfsph_neighbor_list, a.dfsph_list_stride, i);
}

}  // namespace

void enqueue_dfsph_neighbor_lists(const GridView& grid, const ParticleArrays& a, uint32_t n, unsigned threads,
                                  cudaStream_t stream) {
  if (!a.dfsph_neighbor_list || !a.dfsph_neighbor_mask || n == 0) return;
  dfsph_list_kernel<<<blocks_for(n, threads), threads, 0, stream>>>(grid, a, n);
  check_launch("dfsph_list_kernel");
}

}  // namespace sph
