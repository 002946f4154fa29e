// SPDX-License-Identifier: MIT
#include "cpu_neighbor_grid.h"

#include <algorithm>

#include "../core/grid_layout.h"
#include "../core/status.h"

namespace sph {

// The cells the particles span, then the table for them (make_grid_shape_for_extent). Exact
// (a min and max of integers), so the shape is the same for the same positions on any thread
// count.
void CpuNeighborGrid::choose_shape(const Float4* positions, uint32_t n, const CpuParallel& parallel) {
  struct Extent {
    int32_t lo[3], hi[3];
  };
  const Extent none{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  const float inv = inv_cell_size_;
  const Extent e = parallel.for_items(n).reduce(
      n, none,
      [&](uint32_t i, Extent& acc) {
        const int32_t c[3] = {cell_coordinate(positions[i].x, inv), cell_coordinate(positions[i].y, inv),
                              cell_coordinate(positions[i].z, inv)};
        for (int a = 0; a < 3; ++a) {
          acc.lo[a] = std::min(acc.lo[a], c[a]);
          acc.hi[a] = std::max(acc.hi[a], c[a]);
        }
      },
      [](Extent a, const Extent& b) {
        for (int k = 0; k < 3; ++k) {
          a.lo[k] = std::min(a.lo[k], b.lo[k]);
          a.hi[k] = std::max(a.hi[k], b.hi[k]);
        }
        return a;
      });
  const CellCoord lo = n > 0 ? CellCoord{e.lo[0], e.lo[1], e.lo[2]} : CellCoord{0, 0, 0};
  const CellCoord hi = n > 0 ? CellCoord{e.hi[0], e.hi[1], e.hi[2]} : CellCoord{0, 0, 0};
  shape_ = make_grid_shape_for_extent(kernel_radius_, lo, hi, n);
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

void CpuNeighborGrid::build(const Float4* positions, uint32_t n, const CpuParallel& parallel,
                            const GridShape* shape, const uint32_t* visit) {
  if (shape)
    shape_ = *shape;
  else
    choose_shape(positions, n, parallel);
  hashes_.resize(n);
  order_.resize(n);
  cell_start_.assign(static_cast<size_t>(shape_.cell_count) + 1, 0u);
  const GridShape table = shape_;
  uint32_t* hashes = hashes_.data();
  parallel.for_items(n).for_each(
      n, [&](uint32_t i) { hashes[i] = cell_hash_of_position(table, xyz(positions[i])); });

  // Counting sort: histogram, exclusive prefix sum (the cell-start table), stable scatter.
  for (uint32_t i = 0; i < n; ++i) ++cell_start_[hashes_[i] + 1];
  for (uint32_t c = 0; c < shape_.cell_count; ++c)
    if (cell_start_[c + 1] > max_per_cell_) refuse_crowded_slot(positions, n, c, cell_start_[c + 1]);
  for (uint32_t c = 0; c < shape_.cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
  cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  if (visit) {
    for (uint32_t k = 0; k < n; ++k) order_[cursor_[hashes_[visit[k]]]++] = visit[k];
  } else {
    for (uint32_t i = 0; i < n; ++i) order_[cursor_[hashes_[i]]++] = i;
  }
}

}  // namespace sph
