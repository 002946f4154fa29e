// SPDX-License-Identifier: MIT
// sph_collider_create's warning through the context's log callback (SPH_LOG_WARNING, SPH_OK) when a
// world with the walls in the density takes an SDF coarser than half the lattice step that is not
// a plane's (docs/api.md, log_fn).
#pragma once

#include "../core/sdf_asset.h"
#include "sph_c.h"

namespace sph {

void warn_if_coarse_for_boundary_density(const sph_world* world, const SdfAsset* sdf);

}  // namespace sph
