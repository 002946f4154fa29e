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
};

// Calls visit(j) for each particle j in the 3x3x3 block of cells around p. Candidates are
// not filtered by distance: the caller tests r < h (wrapped slots can hold far particles).
template <class Visit>
SPH_HD void for_each_neighbor_candidate(const GridView& grid, Vec3 p, Visit&& visit) {
  const GridShape& g = grid.shape;
  const CellCoord c = cell_of(g, p);
  const int32_t x_lo = wrap_index(c.x - 1, g.nx);
  const int32_t x_hi = wrap_index(c.x + 1, g.nx);
  for (int32_t dz = -1; dz <= 1; ++dz) {
    const int32_t wz = wrap_index(c.z + dz, g.nz);
    for (int32_t dy = -1; dy <= 1; ++dy) {
      const int32_t wy = wrap_index(c.y + dy, g.ny);
      const uint32_t row = hash_wrapped(g, 0, wy, wz);
      if (x_lo < x_hi) {
        const uint32_t begin = grid.cell_start[row + static_cast<uint32_t>(x_lo)];
        const uint32_t end = grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u];
        for (uint32_t j = begin; j < end; ++j) visit(j);
      } else {
        // The row wraps: [x_lo, nx) then [0, x_hi].
        const uint32_t begin_a = grid.cell_start[row + static_cast<uint32_t>(x_lo)];
        const uint32_t end_a = grid.cell_start[row + static_cast<uint32_t>(g.nx)];
        for (uint32_t j = begin_a; j < end_a; ++j) visit(j);
        const uint32_t begin_b = grid.cell_start[row];
        const uint32_t end_b = grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u];
        for (uint32_t j = begin_b; j < end_b; ++j) visit(j);
      }
    }
  }
}

}  // namespace sph
