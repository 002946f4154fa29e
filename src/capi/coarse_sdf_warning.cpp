// SPDX-License-Identifier: MIT
#include "coarse_sdf_warning.h"

#include <cmath>
#include <cstdio>

#include "guard.h"
#include "handles.h"

namespace sph {
namespace {

// Whether an asset's distances are an affine function of the voxel index (a plane's SDF), within
// a thousandth of a voxel: the affine function through voxel (0, 0, 0) and its neighbours along
// each axis. Any kink or curvature fails early, so only a plane's grid is read whole.
bool is_affine(const SdfAsset& sdf, double voxel) {
  const int32_t nx = sdf.nx(), ny = sdf.ny(), nz = sdf.nz();
  const auto& d = sdf.distance();
  const auto at = [&](int32_t i, int32_t j, int32_t k) {
    return static_cast<double>(d[(static_cast<size_t>(k) * ny + j) * nx + i]);
  };
  const double d0 = at(0, 0, 0);
  const double gi = nx > 1 ? at(1, 0, 0) - d0 : 0.0;
  const double gj = ny > 1 ? at(0, 1, 0) - d0 : 0.0;
  const double gk = nz > 1 ? at(0, 0, 1) - d0 : 0.0;
  for (int32_t k = 0; k < nz; ++k)
    for (int32_t j = 0; j < ny; ++j)
      for (int32_t i = 0; i < nx; ++i)
        if (std::fabs(at(i, j, k) - (d0 + i * gi + j * gj + k * gk)) > 1e-3 * voxel) return false;
  return true;
}

}  // namespace

// With the walls in the density an SDF's edges and corners read more wall than they hold, by a
// share that grows with the voxel (the trilinear sampling smooths the kink), and deep still water
// under DFSPH bursts from them (docs/physics.md, "Walls in the density" and DFSPH, Limits). A
// coarse asset is legal; the log says so when a collider takes it. A plane's SDF is exact at any
// voxel: no warning.
void warn_if_coarse_for_boundary_density(const sph_world* world, const SdfAsset* sdf) {
  const WorldConfig& config = world->world->config();
  if (!sdf || !(config.features & SPH_FEATURE_BOUNDARY_DENSITY)) return;
  const double half_step = 0.5 * config.particle_spacing / std::sqrt(2.0);
  const double voxel = sdf->max_voxel_size();
  if (!(voxel > half_step * (1.0 + 1e-4)) || is_affine(*sdf, voxel)) return;
  char what[512];
  std::snprintf(what, sizeof what,
                "the SDF's voxel (%.4g m) is coarser than half the lattice step (%.4g m, particle_spacing / "
                "(2 sqrt 2)): with SPH_FEATURE_BOUNDARY_DENSITY its edges and corners read more wall than "
                "they hold, and deep still water under DFSPH may burst from them; a quarter step holds it "
                "(docs/physics.md, \"Walls in the density\")",
                voxel, half_step);
  report_warning(log_target_of(world), "sph_collider_create", what);
}

}  // namespace sph
