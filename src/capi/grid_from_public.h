// SPDX-License-Identifier: MIT
// The zero rules of sph_grid_desc, shared by every call that reads one (SDF assets, their
// optional channels, force-field grids): an all-zero index_to_local is the identity (1 m
// voxels), and components 0 means the channel's own count.
#pragma once

#include <cstring>
#include <memory>
#include <string>

#include "../core/sdf_asset.h"
#include "../core/status.h"
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

// An asset of g's dimensions and index_to_local; the asset's own errors (a singular or
// non-finite index_to_local) name the caller's field: `prefix` is its path ("def->grid->").
inline std::shared_ptr<SdfAsset> make_grid_asset(const sph_grid_desc& g, const std::string& prefix) {
  try {
    return make_sdf_asset(static_cast<int32_t>(g.dims[0]), static_cast<int32_t>(g.dims[1]),
                          static_cast<int32_t>(g.dims[2]), index_to_local_from_public(g));
  } catch (const Error& e) {
    throw Error(e.status(), prefix + e.what());
  }
}

inline uint32_t grid_components(const sph_grid_desc& g, uint32_t channel_components) {
  return g.components == 0 ? channel_components : g.components;
}

}  // namespace sph
