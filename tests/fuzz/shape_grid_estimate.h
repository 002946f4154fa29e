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

// Voxels of the shape's grid; 0 for a kind the library does not know (it must refuse it).
inline double shape_grid_voxels(const sph_shape_desc& d) {
  uint32_t kind;
  std::memcpy(&kind, &d.shape, sizeof kind);
  const double w = d.wall_thickness, r = d.radius, hh = d.half_height;
  double half[3];
  switch (kind) {
    case SPH_SHAPE_PLANE:
      half[0] = d.half_extents.x, half[1] = d.half_extents.y, half[2] = d.half_extents.z;
      break;
    case SPH_SHAPE_BOX:
      half[0] = d.half_extents.x + w, half[1] = d.half_extents.y + w, half[2] = d.half_extents.z + w;
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
  for (double h : half) voxels *= 2.0 * std::ceil(std::fabs(h) / d.voxel_size) + 2.0 * pad + 1.0;
  return voxels;
}

}  // namespace sph_fuzz

#endif
