// SPDX-License-Identifier: MIT
// The wrapped grid's table dimensions for particles whose cells span [lo, hi] on each axis, within
// a budget of slots: each axis gets the cells the particles span plus one on each side (so the
// 3x3x3 block around any particle never folds onto particles at the far side) unless that makes
// more than `budget` slots; then the narrow axes keep theirs and the wide ones share what is left.
// The CPU backend fits its table at every sort (core/grid_layout.h); the CUDA backend fits the
// dims of its capacity-sized table on the device at every sort (cuda/device_neighbor_grid.cu), so a
// long flume or a thin slab does not fold into a cube's worth of slots.
#pragma once

#include <stdint.h>

#include "grid_hash.h"
#include "host_device.h"

#if !defined(__CUDACC__)
#include <cmath>
#endif

namespace sph {

SPH_HD double grid_fit_power(double x, double y) {
#if defined(__CUDACC__)
  return pow(x, y);
#else
  return std::pow(x, y);
#endif
}

SPH_HD double grid_fit_floor(double x) {
#if defined(__CUDACC__)
  return floor(x);
#else
  return std::floor(x);
#endif
}

// dims[axis] for span[axis] = hi - lo + 3 cells (as a double, so any int32 extent fits), each
// dims >= 3 and their product <= max(budget, 27).
SPH_HD void fit_grid_dims(const double span[3], double budget, int32_t dims[3]) {
  // The axes from the narrowest span up; ties keep axis order (an insertion sort, as
  // std::sort does for three elements, so the CPU's tables are those it always had).
  int order[3] = {0, 1, 2};
  for (int i = 1; i < 3; ++i) {
    const int axis = order[i];
    int j = i;
    while (j > 0 && span[axis] < span[order[j - 1]]) {
      order[j] = order[j - 1];
      --j;
    }
    order[j] = axis;
  }
  double used = 1.0;
  for (int k = 0; k < 3; ++k) {
    const int axis = order[k];
    // What the remaining axes may have each if they share the rest of the budget evenly.
    const double fair = grid_fit_floor(grid_fit_power(budget / used, 1.0 / (3 - k)) + 1e-9);
    double n = span[axis] < fair ? span[axis] : fair;
    if (n < 3.0) n = 3.0;
    dims[axis] = static_cast<int32_t>(n);
    used *= n;
  }
}

// The table for cells spanning [lo, hi] within `budget` slots (cell size 1 / inv_cell_size).
SPH_HD GridShape fit_grid_shape(float inv_cell_size, CellCoord lo, CellCoord hi, double budget) {
  const double span[3] = {static_cast<double>(hi.x) - lo.x + 3.0, static_cast<double>(hi.y) - lo.y + 3.0,
                          static_cast<double>(hi.z) - lo.z + 3.0};
  int32_t dims[3];
  fit_grid_dims(span, budget, dims);
  GridShape g;
  g.inv_cell_size = inv_cell_size;
  g.nx = dims[0];
  g.ny = dims[1];
  g.nz = dims[2];
  g.cell_count =
      static_cast<uint32_t>(dims[0]) * static_cast<uint32_t>(dims[1]) * static_cast<uint32_t>(dims[2]);
  return g;
}

}  // namespace sph
