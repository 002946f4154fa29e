// SPDX-License-Identifier: MIT
// Chooses the wrapped grid's table size. The CUDA backend sizes its table once from the
// world's capacity (its particle arrays are capacity-sized too, so the table, 4 bytes a slot,
// is a small share of what the world already holds) and fits the dims of those slots to the
// particles' extent on the device at every sort (physics/grid_fit.h). The CPU backend sizes it at every sort
// from the particles it has: at most two slots per particle, and no more slots along an axis
// than the particles span there, so a world of capacity 2^30 holding 100 particles has a table
// of at most 200 slots, not 4 GiB (issue 23 item 9).
#pragma once

#include <stdint.h>

#include <algorithm>
#include <cmath>

#include "../physics/grid_fit.h"
#include "../physics/grid_hash.h"

namespace sph {

inline GridShape make_grid_shape(float kernel_radius, uint32_t capacity) {
  // At least 3 per axis so the 27 cells around any cell are distinct table slots.
  const double side = std::ceil(std::cbrt(static_cast<double>(std::max<uint32_t>(capacity, 1))));
  const int32_t n = static_cast<int32_t>(std::max(3.0, std::min(side, 2048.0)));
  GridShape g;
  g.inv_cell_size = 1.0f / kernel_radius;
  g.nx = n;
  g.ny = n;
  g.nz = n;
  g.cell_count = static_cast<uint32_t>(n) * static_cast<uint32_t>(n) * static_cast<uint32_t>(n);
  return g;
}

// A table for `count` particles whose cells span [lo, hi] (inclusive, per axis): the fit of
// physics/grid_fit.h within max(2 count, 64) slots (8 bytes a particle, a few per cent of what a
// particle holds), so a long thin column still gets one slot per particle along its length. Where
// an axis keeps its span, no two cells along it share a slot.
constexpr double kGridSlotsPerParticle = 2.0;

inline GridShape make_grid_shape_for_extent(float kernel_radius, CellCoord lo, CellCoord hi, uint32_t count) {
  const double budget = std::max(kGridSlotsPerParticle * static_cast<double>(count), 64.0);
  return fit_grid_shape(1.0f / kernel_radius, lo, hi, budget);
}

// A CPU rank's table (src/cpu/cpu_halo.cpp): `world` (the undivided world's, for cells spanning
// [lo, hi]) cut along the slabs' `axis` to the band of cells the rank holds, [held_first, held_last]
// (its owned and ghost particles' cells), widened to the cells that the rows of its owned cells
// [first, last] read, [first - 1, last + 1]: so that a rank's table grows with what it holds, not
// with the world. The band's cells are distinct slots, and every row of three cells an owned
// particle walks then holds the same cells in the same order as in the world's table, split into
// two runs exactly where the world's is (a row is split where the table wraps, neighbor_walk.h,
// and the CPU's SIMD lanes restart at each run, so a split elsewhere would add the same terms in
// other lanes): the band wraps at the world's wrap point where one lies in [first, last + 1], else
// at its own first cell; at least 4 cells. Only where the world's table does not fold (each axis holds its
// span and a cell either side: then a slot is one cell); otherwise, where the rank owns nothing (last <
// first), or where the band is not narrower than the world's axis, the world's table itself.
inline GridShape rank_grid_shape(const GridShape& world, CellCoord lo, CellCoord hi, int axis, int32_t first,
                                 int32_t last, int32_t held_first, int32_t held_last) {
  const int32_t dims[3] = {world.nx, world.ny, world.nz};
  const int64_t spans[3] = {static_cast<int64_t>(hi.x) - lo.x + 3, static_cast<int64_t>(hi.y) - lo.y + 3,
                            static_cast<int64_t>(hi.z) - lo.z + 3};
  for (int k = 0; k < 3; ++k)
    if (dims[k] < spans[k]) return world;  // it folds
  if (last < first) return world;
  const int64_t band_first = std::min<int64_t>(held_first, static_cast<int64_t>(first) - 1);
  const int64_t band_last = std::max<int64_t>(held_last, static_cast<int64_t>(last) + 1);
  const int64_t width = band_last - band_first + 1;
  const int32_t n = dims[axis];
  if (width >= n) return world;
  // The world's wrap point nearest above `first`: the first multiple of n from there.
  const int32_t r = wrap_index(first, n);
  const int64_t multiple = r == 0 ? first : static_cast<int64_t>(first) + (n - r);
  const int64_t origin = multiple <= static_cast<int64_t>(last) + 1 ? multiple : band_first;
  // At least 4 slots: a walk from outside the band (a probe point in the rank's slab beyond its
  // particles) then meets the band's particles only at 2 h or more, never near the r < h test's
  // rounding, where the world's walk meets none.
  const int32_t band = static_cast<int32_t>(std::max<int64_t>(width, 4));
  if (band >= n) return world;
  const int32_t shift = wrap_index(static_cast<int32_t>(origin), band);
  GridShape g = world;
  if (axis == 0) {
    g.nx = band;
    g.sx = shift;
  } else if (axis == 1) {
    g.ny = band;
    g.sy = shift;
  } else {
    g.nz = band;
    g.sz = shift;
  }
  g.cell_count = static_cast<uint32_t>(g.nx) * static_cast<uint32_t>(g.ny) * static_cast<uint32_t>(g.nz);
  return g;
}

}  // namespace sph
