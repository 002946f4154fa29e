// SPDX-License-Identifier: MIT
// The number of voxels sph_sdf_create_shape samples for a shape desc, computed as the library
// does (src/core/sdf_shapes.cpp: the shape's half bounds per kind, 2 ceil(half / voxel) +
// 2 padding + 1 per axis). The harnesses use it to skip grids that are legal but too slow to
// build under the sanitizers, while still passing those the library must refuse (over 2^31).
#ifndef SPH_FUZZ_SHAPE_GRID_ESTIMATE_H
#define SPH_FUZZ_SHAPE_GRID_ESTIMATE_H

#include <cmath>
#include <cstdint>
#include <cstring>

#include "sph_c.h"

namespace sph_fuzz {

// A size of the desc with its zero rule applied (0 = the default, sph_shape_desc). The default is a
// float, as the library's (sph::ShapeSpec): 0.01 as a double made the harness count 0.5 / 0.01 as 50
// voxels where the library's 0.5 / 0.01f is 50.0000001, 51 (the capi fuzzer's invariant broke on a
// plane of default depth, session 48; tests/fuzz/regressions/capi).
inline double shape_size_or_default(float value, float fallback) { return value == 0.0f ? fallback : value; }

// Voxels of the shape's grid; 0 for a kind the library does not know (it must refuse it).
inline double shape_grid_voxels(const sph_shape_desc& d) {
  uint32_t kind;
  std::memcpy(&kind, &d.shape, sizeof kind);
  const double w = d.wall_thickness, r = shape_size_or_default(d.radius, 0.5),
               hh = shape_size_or_default(d.half_height, 0.5);
  const double ex = shape_size_or_default(d.half_extents.x, 0.5),
               ey = shape_size_or_default(d.half_extents.y, 0.5),
               ez = shape_size_or_default(d.half_extents.z, 0.5);
  const double voxel = shape_size_or_default(d.voxel_size, 0.01);
  double half[3];
  switch (kind) {
    case SPH_SHAPE_PLANE:
      half[0] = ex, half[1] = ey, half[2] = ez;
      break;
    case SPH_SHAPE_BOX:
      half[0] = ex + w, half[1] = ey + w, half[2] = ez + w;
      break;
    case SPH_SHAPE_SPHERE:
      half[0] = half[1] = half[2] = r;
      break;
    case SPH_SHAPE_CAPSULE:
      half[0] = r, half[1] = hh + r, half[2] = r;
      break;
    case SPH_SHAPE_CYLINDER:
      half[0] = r, half[1] = hh, half[2] = r;
      break;
    case SPH_SHAPE_CUP:
      half[0] = r + w, half[1] = hh, half[2] = r + w;
      break;
    default:
      return 0.0;
  }
  const double pad = d.padding_voxels == 0 ? 4.0 : static_cast<double>(d.padding_voxels);
  double voxels = 1.0;
  for (double h : half) voxels *= 2.0 * std::ceil(std::fabs(h) / voxel) + 2.0 * pad + 1.0;
  return voxels;
}

}  // namespace sph_fuzz

#endif
