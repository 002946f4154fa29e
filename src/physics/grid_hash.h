// SPDX-License-Identifier: MIT
// The wrapped hashed uniform grid (thesis eq. 27-30): cell = floor(x / cell_size) per axis,
// folded into an nx * ny * nz table in linear x-fastest order so neighbouring cells stay
// close in memory. An unbounded domain maps onto a table sized by particle count.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "vec3.h"

#if defined(__CUDACC__)
#define SPH_FLOORF floorf
#define SPH_FMINF fminf
#define SPH_FMAXF fmaxf
#else
#include <cmath>
#define SPH_FLOORF std::floor
// fmax and fmin by comparison: GCC calls libm for std::fmax / std::fmin (without
// -ffinite-math-only), twice per axis per particle in every sort and walk. With the finite
// bounds of cell_coordinate they give fmax's and fmin's value for every input, NaN included
// (fmax(NaN, lo) = lo).
#define SPH_FMINF(a, b) ((a) <= (b) ? (a) : (b))
#define SPH_FMAXF(a, b) ((a) >= (b) ? (a) : (b))
#endif

namespace sph {

// Cell coordinates are clamped to this magnitude so a runaway particle cannot overflow int32.
constexpr float kMaxCellCoordinate = 1073741824.0f;  // 2^30

struct GridShape {
  float inv_cell_size;  // 1 / cell size (cell size = kernel radius h)
  int32_t nx, ny, nz;   // table dimensions, each >= 3 so the 27 neighbours are distinct slots
  uint32_t cell_count;  // nx * ny * nz
  // Where each axis wraps: cell c lands in slot wrap_index(c, n) - shift (wrapped into [0, n)), so
  // the cells c = shift (mod n) are slot 0. Zero except on a CPU rank's table, which covers its own
  // band of the world's with the world's wrap points (src/cpu/cpu_halo.cpp, rank_grid_shape).
  int32_t sx = 0, sy = 0, sz = 0;
};

struct CellCoord {
  int32_t x, y, z;
};

// The smallest normal float (FLT_MIN).
constexpr float kSmallestNormalFloat = 1.17549435e-38f;

// v, or zero where v is a denormal: what a CUDA file compiled with -ftz=true does to every input
// and result of its float arithmetic in hardware.
SPH_HD float flushed_to_zero(float v) {
  return (v > -kSmallestNormalFloat && v < kSmallestNormalFloat) ? 0.0f : v;
}

// The cell along one axis. Denormals are flushed before and after the product by hand, so the cell
// is the same whatever arithmetic flags the caller was compiled with: the CUDA density pass (-ftz)
// writes DFSPH's neighbour masks over the runs of its cells, and the conjugate gradients' files
// (IEEE) walk those masks again; without the flush, x = -1e-40 is cell 0 in one and -1 in the
// other, and the masks' bits would name other candidates. The CPU gets the same cells. (The
// comparisons are no-ops under -ftz and cost two selects an axis elsewhere.)
SPH_HD int32_t cell_coordinate(float x, float inv_cell_size) {
  float c = SPH_FLOORF(flushed_to_zero(flushed_to_zero(x) * inv_cell_size));
  c = SPH_FMINF(SPH_FMAXF(c, -kMaxCellCoordinate), kMaxCellCoordinate);
  return static_cast<int32_t>(c);
}

SPH_HD CellCoord cell_of(const GridShape& g, Vec3 p) {
  return CellCoord{cell_coordinate(p.x, g.inv_cell_size), cell_coordinate(p.y, g.inv_cell_size),
                   cell_coordinate(p.z, g.inv_cell_size)};
}

// Non-negative remainder: wraps negative cell coordinates into [0, n).
SPH_HD int32_t wrap_index(int32_t c, int32_t n) {
  const int32_t m = c % n;
  return m < 0 ? m + n : m;
}

// wrap_index(w + step, n) for a slot w already in [0, n) and step in {-1, 0, 1}.
SPH_HD int32_t wrap_step(int32_t w, int32_t step, int32_t n) {
  const int32_t s = w + step;
  return s < 0 ? n - 1 : (s >= n ? 0 : s);
}

SPH_HD uint32_t hash_wrapped(const GridShape& g, int32_t wx, int32_t wy, int32_t wz) {
  return static_cast<uint32_t>(wx) +
         static_cast<uint32_t>(g.nx) *
             (static_cast<uint32_t>(wy) + static_cast<uint32_t>(g.ny) * static_cast<uint32_t>(wz));
}

// The slot index along one axis of cell coordinate c (GridShape's shift; in [0, n)).
SPH_HD int32_t shifted_index(int32_t c, int32_t n, int32_t shift) {
  const int32_t w = wrap_index(c, n) - shift;
  return w < 0 ? w + n : w;
}

SPH_HD uint32_t cell_hash(const GridShape& g, CellCoord c) {
  return hash_wrapped(g, shifted_index(c.x, g.nx, g.sx), shifted_index(c.y, g.ny, g.sy),
                      shifted_index(c.z, g.nz, g.sz));
}

SPH_HD uint32_t cell_hash_of_position(const GridShape& g, Vec3 p) { return cell_hash(g, cell_of(g, p)); }

}  // namespace sph
