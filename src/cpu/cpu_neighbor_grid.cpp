#include "cpu_neighbor_grid.h"

namespace sph {

void CpuNeighborGrid::build(const Float4* positions, uint32_t n, unsigned workers) {
  hashes_.resize(n);
  order_.resize(n);
  cell_start_.assign(static_cast<size_t>(shape_.cell_count) + 1, 0u);
  const int count = static_cast<int>(n);
#pragma omp parallel for num_threads(n >= kParallelMinimum ? workers : 1u) schedule(dynamic, kParticleChunk)
  for (int i = 0; i < count; ++i) hashes_[i] = cell_hash_of_position(shape_, xyz(positions[i]));

  // Counting sort: histogram, exclusive prefix sum (the cell-start table), stable scatter.
  for (uint32_t i = 0; i < n; ++i) ++cell_start_[hashes_[i] + 1];
  for (uint32_t c = 0; c < shape_.cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
  cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (uint32_t i = 0; i < n; ++i) order_[cursor_[hashes_[i]]++] = i;
}

}  // namespace sph
