// The adaptive step size (thesis eq. 32) and the rule that lands substeps exactly on the end
// of a frame. Shared so both backends take the very same steps.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "vec3.h"

namespace sph {

struct StepLimits {
  float step_factor;  // lambda
  float kernel_radius;
  float dt_min;
  float dt_max;
  float sound_speed;         // > 0: the acoustic limit dt <= lambda h / c applies
  uint32_t use_force_limit;  // the force limit dt <= lambda sqrt(h / |a|_max) applies
  float stability_dt;        // > 0: the ceiling of stability_ceiling(), applied whatever dt_max says
};

// The explicit scheme's hard stability limits, which hold whatever dt_max and lambda are:
// - acoustic: dt <= 0.4 h / c. A pressure wave must not cross more than a fraction of a kernel
//   radius per step; measured on a dam break (tests/extremes), fixed steps of 1 h/c stay
//   bounded and 2 h/c blow up (energy x1000), so 0.4 leaves a margin of 2.5.
// - viscous (Mueller's Laplacian, kinematic viscosity nu = mu / rho0): dt <= 0.05 h^2 / nu, the
//   explicit diffusion limit; measured, 0.1 h^2 / nu is stable and 0.15 blows up, so 0.05
//   leaves a margin of 2.
// sound_speed or kinematic_viscosity 0 drops that limit; both 0 gives 0 (no ceiling).
constexpr float kAcousticStabilityFactor = 0.4f;
constexpr float kViscousStabilityFactor = 0.05f;

SPH_HD float stability_ceiling(float kernel_radius, float sound_speed, float kinematic_viscosity) {
  float dt = 0.0f;
  if (sound_speed > 0.0f) dt = kAcousticStabilityFactor * kernel_radius / sound_speed;
  if (kinematic_viscosity > 0.0f) {
    const float viscous = kViscousStabilityFactor * kernel_radius * kernel_radius / kinematic_viscosity;
    if (dt == 0.0f || viscous < dt) dt = viscous;
  }
  return dt;
}

// dt = lambda h / v_max (eq. 32), with the acoustic and force limits where asked for and the
// stability ceiling always, clamped to [dt_min, dt_max]; v_max = 0 and no other limit gives
// dt_max. dt_min is the caller's explicit floor and wins over the ceiling (fixed-step runs pin
// dt_min = dt_max); a non-finite step above the ceiling says so in its error.
SPH_HD float controller_dt(const StepLimits& s, float max_speed, float max_acceleration) {
  float dt = s.dt_max;
  if (s.stability_dt > 0.0f && s.stability_dt < dt) dt = s.stability_dt;
  if (max_speed > 0.0f) {
    const float candidate = s.step_factor * s.kernel_radius / max_speed;
    if (candidate < dt) dt = candidate;
  }
  if (s.sound_speed > 0.0f) {
    const float candidate = s.step_factor * s.kernel_radius / s.sound_speed;
    if (candidate < dt) dt = candidate;
  }
  if (s.use_force_limit && max_acceleration > 0.0f) {
    const float candidate = s.step_factor * SPH_SQRTF(s.kernel_radius / max_acceleration);
    if (candidate < dt) dt = candidate;
  }
  if (dt < s.dt_min) dt = s.dt_min;
  return dt;
}

SPH_HD float controller_dt(const StepLimits& s, float max_speed) { return controller_dt(s, max_speed, 0.0f); }

// Shortens dt so the frame ends exactly: take the remainder when it fits, and split a
// remainder between dt and 2 dt in halves so no sliver of a step is left at the end.
SPH_HD double landing_dt(double dt, double remaining) {
  if (remaining <= dt) return remaining;
  if (remaining < 2.0 * dt) return 0.5 * remaining;
  return dt;
}

}  // namespace sph
