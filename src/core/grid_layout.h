// SPDX-License-Identifier: MIT
// Chooses the wrapped grid's table size from the world's capacity: about one table slot per
// particle, so memory scales with particles and never with the extent of the domain.
#pragma once

#include <stdint.h>

#include <algorithm>
#include <cmath>

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

}  // namespace sph
