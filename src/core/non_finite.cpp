// SPDX-License-Identifier: MIT
#include "non_finite.h"

namespace sph {
namespace {

const char* stage_name(uint32_t stage) {
  static const char* const kStages[] = {
      "density stage (SPH_STAGE_DENSITY)", "forces stage (SPH_STAGE_FORCES)",
      "integrate stage (SPH_STAGE_INTEGRATE)", "collide stage (SPH_STAGE_COLLIDE)"};
  return kStages[stage & 3u];
}

// Only dt_min can force a step above the stability ceiling; a failure there says so.
std::string above_stable_step(float dt, const StepLimits& limits) {
  if (!(limits.stability_dt > 0.0f) || dt <= limits.stability_dt) return "";
  return ", above this world's stable step " + std::to_string(limits.stability_dt) +
         " s (0.4 h / c, 0.05 h^2 rho0 / mu), forced by dt_min";
}

}  // namespace

std::string non_finite_message(const NonFiniteFailure& f, const StepLimits& limits) {
  std::string particles = std::to_string(f.count) + (f.count == 1 ? " particle, id " : " particles, ids ");
  for (size_t k = 0; k < f.ids.size(); ++k) particles += (k > 0 ? ", " : "") + std::to_string(f.ids[k]);
  if (f.count > f.ids.size()) particles += ", ...";
  return "the step produced non-finite values in the " + std::string(stage_name(f.stage)) + " of substep " +
         std::to_string(f.substep) + " (dt " + std::to_string(f.dt) + " s" + above_stable_step(f.dt, limits) +
         "): " + particles + "; the world was restored to its state before sph_world_step";
}

}  // namespace sph
