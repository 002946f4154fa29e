// SPDX-License-Identifier: MIT
// The adaptive step size (thesis eq. 32) and the rule that lands substeps exactly on the end
// of a frame. Shared so both backends take the very same steps.
#pragma once

#include <math.h>
#include <stdint.h>

#include "host_device.h"
#include "param_table.h"
#include "vec3.h"
#include "world_shape.h"

namespace sph {

// Step-size limits beyond eq. 32, equal to the SPH_STEP_LIMIT_* values.
enum StepLimitBits : uint32_t { kStepLimitAcoustic = 1u << 0, kStepLimitForce = 1u << 1, kStepLimitAll = 3u };

// The world's own runtime parameters (the rest of sph_world_params belongs to the equation of
// state and the viscosity): gravity, and how substeps are chosen.
// The most substeps one frame may be allowed: 100 times the default, so that max_substeps alone
// cannot let one sph_world_step run for hours (issue 23 item 9; the step budget bounds the
// wall-clock time itself).
constexpr double kMaxSubstepsBound = 1000000.0;

struct Stepping {
  static constexpr const char* kName = "stepping";

  struct Params {
    Vec3 gravity{0.0f, -9.81f, 0.0f};  // m/s^2
    float step_factor = 0.4f;          // lambda of dt = lambda h / v_max
    float dt_min = 1e-6f;              // s
    float dt_max = 1e-3f;              // s
    uint32_t max_substeps = 10000;     // per frame
    uint32_t step_limits = 0;          // StepLimitBits
  };
  static constexpr ParamField<Params> kFields[] = {
      count_field("max_substeps", &Params::max_substeps, within(1.0, kMaxSubstepsBound), ZeroMeans::Default),
      vector_field("gravity", &Params::gravity, ZeroMeans::Value, "m/s^2"),
      real_field("step_factor", &Params::step_factor, above_up_to(0.0, 10.0), ZeroMeans::Default, ""),
      real_field("dt_min", &Params::dt_min, above(0.0), ZeroMeans::Default, "s"),
      real_field("dt_max", &Params::dt_max, above(0.0), ZeroMeans::Default, "s"),
      bits_field("step_limits", &Params::step_limits, kStepLimitAll),
  };
  static bool check(const Params& p, const WorldShape&, ParamConflict& out) {
    if (p.dt_max < p.dt_min) {
      out = ParamConflict{"dt_max", p.dt_max, "is smaller than", "dt_min", p.dt_min};
      return false;
    }
    return true;
  }
};

struct StepLimits {
  float step_factor;  // lambda
  float kernel_radius;
  float dt_min;
  float dt_max;
  float sound_speed;         // > 0: the acoustic limit dt <= lambda h / c applies
  uint32_t use_force_limit;  // the force limit dt <= lambda sqrt(h / |a|_max) applies
  float stability_dt;        // > 0: the methods' stability ceiling (methods.h), whatever dt_max says
  // DFSPH's depth limit dt <= f h / sqrt(|g| H) (below): f (0: the limit is off: another solver,
  // no gravity, or SPH_DFSPH_NO_DEPTH_STEP_LIMIT), |g|, and g / |g|, along which H is measured.
  float depth_step_factor;
  float gravity_magnitude;
  Vec3 down;
};

// DFSPH's depth limit. Still water held by DFSPH blows apart when dt > about 0.37 h / sqrt(|g| D),
// D the water's depth (H200, 0.24-0.96 m deep tanks at lattice steps of 1 cm and 5 mm: every run
// at dt sqrt(g D) / h <= 0.36 settled, every run at >= 0.39 blew; docs/validation.md, "Session
// 19"), a bound that neither the CFL (the water is at rest) nor the force limit (|a| is about g)
// sees: sqrt(g D) = sqrt(p / rho0) at the floor, the pressure's own speed. D is read as H, the
// fluid's extent along gravity (max - min of x . g / |g| over the particles), so the limit needs
// no feedback through the solve (a limit on the pressure itself collapsed the step: DFSPH's
// pressure holds the step's own correction); H >= D, so the limit is conservative where the
// fluid's lowest and highest particles are not one column (two pools at different heights).
// height_along is the projection whose max - min is H; every backend and rank uses it.
SPH_HD float height_along(const StepLimits& s, Vec3 x) { return dot(x, s.down); }

// H from the lowest and highest projection (0 for no particle: lo > hi).
SPH_HD float height_of_span(float lo, float hi) { return hi > lo ? hi - lo : 0.0f; }

// f h / sqrt(|g| H), or 0 where the limit does not apply (off, or H <= 0 or not finite).
SPH_HD float depth_step_limit(const StepLimits& s, float fluid_height) {
  if (!(s.depth_step_factor > 0.0f) || !(fluid_height > 0.0f) || !(s.gravity_magnitude > 0.0f)) return 0.0f;
  const float gh = s.gravity_magnitude * fluid_height;
  if (!(gh < INFINITY)) return 0.0f;
  return s.depth_step_factor * s.kernel_radius / SPH_SQRTF(gh);
}

// dt = lambda h / v_max (eq. 32), with the acoustic and force limits where asked for, the
// stability ceiling always and DFSPH's depth limit where it is on (fluid_height: H, the fluid's
// extent along gravity, measured this substep), clamped to [dt_min, dt_max]; v_max = 0 and no
// other limit gives dt_max. dt_min is the caller's explicit floor and wins over the ceiling and
// the depth limit (fixed-step runs pin dt_min = dt_max); a non-finite step above the ceiling says
// so in its error.
SPH_HD float controller_dt(const StepLimits& s, float max_speed, float max_acceleration, float fluid_height) {
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
  const float depth = depth_step_limit(s, fluid_height);
  if (depth > 0.0f && depth < dt) dt = depth;
  if (dt < s.dt_min) dt = s.dt_min;
  return dt;
}

SPH_HD float controller_dt(const StepLimits& s, float max_speed, float max_acceleration) {
  return controller_dt(s, max_speed, max_acceleration, 0.0f);
}
SPH_HD float controller_dt(const StepLimits& s, float max_speed) {
  return controller_dt(s, max_speed, 0.0f, 0.0f);
}

// A remainder this share of a step above a whole number of steps counts as that number: the
// frame then lands in those steps, each longer than dt by at most this share, where a rounding
// hair (0.003f against a limit one ulp below it) would otherwise cost a substep more.
constexpr double kLandingSlack = 1e-4;

// Shortens dt so the frame ends exactly: the remainder is spread evenly over the fewest substeps
// of at most dt that hold it, n = ceil(remaining / dt), each remaining / n (re-planned every
// substep, since the limit moves). The same count as taking whole steps while 2 dt remain and
// halving the last remainder between dt and 2 dt, but never a short step right after long ones:
// DFSPH's solves remove the last step's leftover compression within the next one, so a 2 ms
// step after 4 ms ones over-pushes, and a settled tank read at those frame ends missed rho0 g d by
// 6 % (docs/physics.md, "How a frame splits into substeps").
SPH_HD double landing_dt(double dt, double remaining) {
  if (remaining <= dt) return remaining;
  const double steps = ceil(remaining / dt - kLandingSlack);
  return steps <= 1.0 ? remaining : remaining / steps;
}

}  // namespace sph
