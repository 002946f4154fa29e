// SPDX-License-Identifier: MIT
// SDF assets built from triangle meshes (vertices and indices), with no OpenVDB: exact
// point-triangle distances in a narrow band around the surface, the closest triangle swept
// outward from the band for the far field, and the sign from the generalised winding number,
// so meshes with small holes or flipped orientation still have an inside.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>

#include "sdf_asset.h"

namespace sph {

struct MeshSpec {
  const float* vertices = nullptr;  // x, y, z per vertex, `vertex_stride` bytes apart
  size_t vertex_stride = 3 * sizeof(float);
  uint32_t vertex_count = 0;
  const uint32_t* indices = nullptr;  // three per triangle
  uint32_t index_count = 0;
  float voxel_size = 0.01f;    // m
  float band_width = 3.0f;     // voxels of exact distance on each side of the surface
  int32_t padding_voxels = 4;  // grid margin around the mesh's bounds
};

// Validates the mesh (names the failing field as "desc->...": Error(InvalidArgument) for NULL
// arrays, counts, indices out of range, non-finite vertices or bad sizes; Error(Capacity) for
// a grid over max_voxels) and builds the asset: voxel centres on a grid that covers the mesh's
// bounds plus padding, distances negative where the winding number is at least 1/2 in
// magnitude (either orientation of the triangles).
std::shared_ptr<SdfAsset> build_mesh_sdf(const MeshSpec& spec, uint64_t max_voxels);

}  // namespace sph
