// SPDX-License-Identifier: MIT
// The size limits of one SDF asset: one definition for every way an asset is made
// (sph_sdf_create, sph_sdf_create_shape, sph_sdf_create_mesh) and for the checkpoint reader
// that restores one, so that whatever a world holds it can save and load again.
#pragma once

#include <stdint.h>

namespace sph {

constexpr uint32_t kMaxSdfDim = 1u << 30;       // voxels along one axis
constexpr uint64_t kMaxSdfVoxels = 1ull << 31;  // voxels in all

}  // namespace sph
