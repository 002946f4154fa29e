// SPDX-License-Identifier: MIT
#include "cpu_neighbor_grid.h"

#include <algorithm>

#include "../core/grid_layout.h"
#include "../core/status.h"

namespace sph {

// The cells the particles span, then the table for them (make_grid_shape_for_extent). Exact
// (a min and max of integers), so the shape is the same for the same positions on any thread
// count.
void CpuNeighborGrid::choose_shape(const Float4* positions, uint32_t n, unsigned workers) {
  int32_t lo_x = 0, lo_y = 0, lo_z = 0, hi_x = 0, hi_y = 0, hi_z = 0;
  if (n > 0) {
    lo_x = lo_y = lo_z = INT32_MAX;
    hi_x = hi_y = hi_z = INT32_MIN;
  }
  const int count = static_cast<int>(n);
  const float inv = inv_cell_size_;
#pragma omp parallel for num_threads(n >= kParallelMinimum ? workers : 1u) schedule(static) \
    reduction(min                                                                           \
              : lo_x, lo_y, lo_z) reduction(max                                             \
                                            : hi_x, hi_y, hi_z)
  for (int i = 0; i < count; ++i) {
    const int32_t x = cell_coordinate(positions[i].x, inv), y = cell_coordinate(positions[i].y, inv),
                  z = cell_coordinate(positions[i].z, inv);
    lo_x = std::min(lo_x, x);
    lo_y = std::min(lo_y, y);
    lo_z = std::min(lo_z, z);
    hi_x = std::max(hi_x, x);
    hi_y = std::max(hi_y, y);
    hi_z = std::max(hi_z, z);
  }
  shape_ =
      make_grid_shape_for_extent(kernel_radius_, CellCoord{lo_x, lo_y, lo_z}, CellCoord{hi_x, hi_y, hi_z}, n);
}

void CpuNeighborGrid::refuse_crowded_slot(const Float4* positions, uint32_t n, uint32_t slot,
                                          uint32_t held) const {
  Vec3 where{0.0f, 0.0f, 0.0f};
  for (uint32_t i = 0; i < n; ++i)
    if (hashes_[i] == slot) {
      where = xyz(positions[i]);
      break;
    }
  throw Error(Status::Capacity, crowded_cell_message(held, where, max_per_cell_));
}

void CpuNeighborGrid::build(const Float4* positions, uint32_t n, unsigned workers) {
  choose_shape(positions, n, workers);
  hashes_.resize(n);
  order_.resize(n);
  cell_start_.assign(static_cast<size_t>(shape_.cell_count) + 1, 0u);
  const int count = static_cast<int>(n);
  const GridShape shape = shape_;
#pragma omp parallel for num_threads(n >= kParallelMinimum ? workers : 1u) schedule(dynamic, kParticleChunk)
  for (int i = 0; i < count; ++i) hashes_[i] = cell_hash_of_position(shape, xyz(positions[i]));

  // Counting sort: histogram, exclusive prefix sum (the cell-start table), stable scatter.
  for (uint32_t i = 0; i < n; ++i) ++cell_start_[hashes_[i] + 1];
  for (uint32_t c = 0; c < shape_.cell_count; ++c)
    if (cell_start_[c + 1] > max_per_cell_) refuse_crowded_slot(positions, n, c, cell_start_[c + 1]);
  for (uint32_t c = 0; c < shape_.cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
  cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (uint32_t i = 0; i < n; ++i) order_[cursor_[hashes_[i]]++] = i;
}

}  // namespace sph
