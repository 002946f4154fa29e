// The adaptive step size (thesis eq. 32) and the rule that lands substeps exactly on the end
// of a frame. Shared so both backends take the very same steps.
#pragma once

#include "host_device.h"

namespace sph {

struct StepLimits {
  float step_factor;  // lambda
  float kernel_radius;
  float dt_min;
  float dt_max;
};

// dt = lambda h / v_max clamped to [dt_min, dt_max]; v_max = 0 gives dt_max.
SPH_HD float controller_dt(const StepLimits& s, float max_speed) {
  float dt = s.dt_max;
  if (max_speed > 0.0f) {
    const float candidate = s.step_factor * s.kernel_radius / max_speed;
    if (candidate < dt) dt = candidate;
  }
  if (dt < s.dt_min) dt = s.dt_min;
  return dt;
}

// Shortens dt so the frame ends exactly: take the remainder when it fits, and split a
// remainder between dt and 2 dt in halves so no sliver of a step is left at the end.
SPH_HD double landing_dt(double dt, double remaining) {
  if (remaining <= dt) return remaining;
  if (remaining < 2.0 * dt) return 0.5 * remaining;
  return dt;
}

}  // namespace sph
