// SPDX-License-Identifier: MIT
// Visits every particle in the 27 cells around a position, in a fixed order, using a dense
// cell-start table: cell_start[c] is the index of the first particle whose hash is >= c, and
// cell_start[cell_count] is the particle count. Because the table is dense, the three cells of
// one x-row are a single contiguous index range unless the row wraps around the table.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "grid_hash.h"
#include "host_device.h"

namespace sph {

struct GridView {
  GridShape shape;
  const uint32_t* cell_start;  // cell_count + 1 entries
  // The CUDA backend's table shape of this sort, fitted on the device to the particles' extent
  // (cuda/device_neighbor_grid.h); null: `shape` is the table's. Device code only.
  const GridShape* live_shape = nullptr;
};

// The shape the table was filled with.
SPH_HD GridShape shape_of(const GridView& grid) {
#if defined(__CUDA_ARCH__)
  if (grid.live_shape) return *grid.live_shape;
#endif
  return grid.shape;
}

// Calls visit_range(begin, end) for each run of consecutive particle indices in the 3x3x3
// block of cells around p: one run per row of three cells (two where the row wraps around the
// table), nine rows in a fixed order. Candidates are not filtered by distance: the caller
// tests r < h (wrapped slots can hold far particles).
template <class VisitRange>
SPH_HD void for_each_neighbor_range(const GridView& grid, Vec3 p, VisitRange&& visit_range) {
  const GridShape g = shape_of(grid);
  const CellCoord c = cell_of(g, p);
  // One remainder per axis; the neighbouring slots follow by stepping (each n >= 3).
  const int32_t cx = wrap_index(c.x, g.nx), cy = wrap_index(c.y, g.ny), cz = wrap_index(c.z, g.nz);
  const int32_t x_lo = wrap_step(cx, -1, g.nx);
  const int32_t x_hi = wrap_step(cx, 1, g.nx);
  for (int32_t dz = -1; dz <= 1; ++dz) {
    const int32_t wz = wrap_step(cz, dz, g.nz);
    for (int32_t dy = -1; dy <= 1; ++dy) {
      const int32_t wy = wrap_step(cy, dy, g.ny);
      const uint32_t row = hash_wrapped(g, 0, wy, wz);
      if (x_lo < x_hi) {
        visit_range(grid.cell_start[row + static_cast<uint32_t>(x_lo)],
                    grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u]);
      } else {
        // The row wraps: [x_lo, nx) then [0, x_hi].
        visit_range(grid.cell_start[row + static_cast<uint32_t>(x_lo)],
                    grid.cell_start[row + static_cast<uint32_t>(g.nx)]);
        visit_range(grid.cell_start[row], grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u]);
      }
    }
  }
}

// Calls visit(j) for each particle j in the 3x3x3 block of cells around p, in the order of
// for_each_neighbor_range.
template <class Visit>
SPH_HD void for_each_neighbor_candidate(const GridView& grid, Vec3 p, Visit&& visit) {
  for_each_neighbor_range(grid, p, [&](uint32_t begin, uint32_t end) {
    SPH_UNROLL(4)
    for (uint32_t j = begin; j < end; ++j) visit(j);
  });
}

}  // namespace sph
