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
};

// dt = lambda h / v_max (eq. 32), with the acoustic and force limits where asked for,
// clamped to [dt_min, dt_max]; v_max = 0 and no other limit gives dt_max.
SPH_HD float controller_dt(const StepLimits& s, float max_speed, float max_acceleration) {
  float dt = s.dt_max;
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
