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

}  // namespace sph
