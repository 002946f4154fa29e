// SPDX-License-Identifier: MIT
// The zero rules of sph_grid_desc, shared by every call that reads one (SDF assets, their
// optional channels, force-field grids): an all-zero index_to_local is the identity (1 m
// voxels), and components 0 means the channel's own count.
#pragma once

#include <cstring>

#include "../core/sdf_asset.h"
#include "sph_c.h"

namespace sph {

inline Affine3x4 index_to_local_from_public(const sph_grid_desc& g) {
  Affine3x4 affine;
  std::memcpy(affine.m, g.index_to_local, sizeof affine.m);
  for (float m : affine.m)
    if (m != 0.0f) return affine;
  std::memset(affine.m, 0, sizeof affine.m);
  affine.m[0] = affine.m[5] = affine.m[10] = 1.0f;
  return affine;
}

inline uint32_t grid_components(const sph_grid_desc& g, uint32_t channel_components) {
  return g.components == 0 ? channel_components : g.components;
}

}  // namespace sph
