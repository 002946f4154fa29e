// SPDX-License-Identifier: MIT
// Where DFSPH's density solve by conjugate gradients (sph_dfsph_params.linear_solver =
// SPH_DFSPH_CONJUGATE_GRADIENTS; physics/dfsph_cg.h) cannot run yet: the walls in the
// density (SPH_FEATURE_BOUNDARY_DENSITY) and the collider loads (SPH_FEATURE_COLLIDER_LOADS; docs/physics.md,
// DFSPH, Limits). Refused when the parameters are set (sph_world_set_dfsph_params and
// sph_world_set_physics_params) and when a checkpoint that carries them is loaded or restored, so that the
// user learns of it there, with the world unchanged, instead of at the next step. The backends keep their own
// refusal at the step for the paths that reach them otherwise. (Distributed worlds run it on both backends
// since session 16: docs/distributed.md.)
#pragma once

#include <string>

#include "../core/world.h"
#include "../physics/dfsph.h"

namespace sph {

// Error(Unsupported) naming the field when `params` ask for a solve where it does not run; `field` is
// the field as the caller's message names it.
inline void require_supported_dfsph_solver(const World& world, const RuntimeParams& params,
                                           const char* field) {
  if (world.config().solver != Solver::Dfsph) return;
  const uint32_t solver = params_of<Dfsph>(params).linear_solver;
  if (solver != kDfsphConjugateGradients) return;
  const uint32_t features = world.config().features;
  const char* where = nullptr;
  if (features & kFeatureBoundaryDensity)
    where = "SPH_FEATURE_BOUNDARY_DENSITY";
  else if (features & kFeatureColliderLoads)
    // Its search directions and contact holds move velocities outside the Jacobi update the
    // loads' sums follow (physics/collider_loads.h).
    where = "SPH_FEATURE_COLLIDER_LOADS";
  if (where)
    throw Error(Status::Unsupported, std::string(field) +
                                         ": SPH_DFSPH_CONJUGATE_GRADIENTS (DFSPH's conjugate gradients "
                                         "solve) does not work with " +
                                         where + " yet; use SPH_DFSPH_JACOBI");
}

}  // namespace sph
