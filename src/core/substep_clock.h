// SPDX-License-Identifier: MIT
// The substep clock of a frame, written once for both backends: the CPU backend keeps it in its
// frame loop, the CUDA backend in FrameState on the device (frame_control.cu), and both advance
// it with the functions below, so they take the very same steps (the step control itself is
// src/physics/step_control.h). A frame runs substeps while time remains and max_substeps is not
// spent; each substep's length lands the frame exactly on its end (landing_dt).
#pragma once

#include <float.h>
#include <stdint.h>

#include "../physics/collider_response.h"
#include "../physics/host_device.h"
#include "../physics/step_control.h"
#include "frame_report.h"

namespace sph {

struct SubstepClock {
  double remaining;      // seconds of the frame still to simulate
  double time_advanced;  // seconds simulated so far this frame
  double dt;             // this substep's step
  float dt_float;        // the same step as the kernels integrate with
  float dt_min;          // of the substeps run so far
  float dt_max;
  uint32_t substeps;  // run so far
  SubstepTime time;   // this substep's place in the frame, for moving colliders
};

SPH_HD void start_clock(SubstepClock& c, double frame_dt) {
  c.remaining = frame_dt;
  c.time_advanced = 0.0;
  c.substeps = 0;
  c.dt_min = FLT_MAX;
  c.dt_max = 0.0f;
}

SPH_HD bool clock_running(const SubstepClock& c, uint32_t max_substeps) {
  return c.remaining > 0.0 && c.substeps < max_substeps;
}

// The next substep's step and its place in the frame. speed: the faster of the fluid's |v|max
// and the colliders' surfaces, so a fast paddle cannot skip a particle between substeps.
// fluid_height: H of DFSPH's depth limit, measured from the positions the substep starts from
// (0 where the limit is off).
SPH_HD void pick_next_step(SubstepClock& c, double frame_dt, const StepLimits& limits, float speed,
                           float max_acceleration, float fluid_height) {
  c.dt = landing_dt(static_cast<double>(controller_dt(limits, speed, max_acceleration, fluid_height)),
                    c.remaining);
  c.dt_float = static_cast<float>(c.dt);
  const double elapsed = c.time_advanced;
  c.time.tau0 = static_cast<float>(elapsed);
  c.time.tau1 = static_cast<float>(elapsed + c.dt);
  c.time.s0 = static_cast<float>(elapsed / frame_dt);
  c.time.s1 = c.remaining <= c.dt ? 1.0f : static_cast<float>((elapsed + c.dt) / frame_dt);
  c.time.dt = c.dt_float;
}

// After a substep that succeeded.
SPH_HD void advance_clock(SubstepClock& c) {
  c.remaining -= c.dt;
  c.substeps += 1;
  c.time_advanced += c.dt;
  c.dt_min = c.dt_float < c.dt_min ? c.dt_float : c.dt_min;
  c.dt_max = c.dt_max < c.dt_float ? c.dt_float : c.dt_max;
}

// The frame's timing in the report: completed when the frame's time was reached (not when
// max_substeps ran out first).
inline void report_clock(const SubstepClock& c, FrameReport& report) {
  report.substeps = c.substeps;
  report.completed = c.remaining <= 0.0;
  report.time_advanced = c.time_advanced;
  report.dt_min = c.substeps == 0 ? 0.0f : c.dt_min;
  report.dt_max = c.dt_max;
}

}  // namespace sph
