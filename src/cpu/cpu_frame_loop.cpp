// The CPU backend's frame: adaptive substeps until the frame time is reached, sinks after each,
// and the rollback that puts the particles back when a substep fails (the twin of
// cuda/frame_loop.cu).
#include <algorithm>
#include <limits>
#include <string>

#include "../core/scene_frame.h"
#include "../core/status.h"
#include "cpu_backend_impl.h"

namespace sph {

FrameReport CpuBackend::step_frame(double frame_dt, const RuntimeParams& params) {
  return step_scene_frame(frame_dt, params, SceneFrame{});
}

FrameReport CpuBackend::step_scene_frame(double frame_dt, const RuntimeParams& params,
                                         const SceneFrame& scene_in) {
  FrameReport report;
  FluidConstants fluid = make_fluid_constants(config_, params);
  const StepLimits limits = make_step_limits(config_, params);
  SceneFrame scene = scene_in;
  bind_scene_views(scene, [](const SdfAsset& a) { return a.host_view(); });
  report.removed_by_sink.assign(scene.sinks.size(), 0u);
  const uint32_t count_before = count_;
  const auto saved = store_.snapshot();
  const float saved_max_speed = max_speed_;
  const bool saved_max_speed_valid = max_speed_valid_;
  const float saved_max_acceleration = max_acceleration_;
  const uint32_t saved_link_from = link_from_;
  spring_constants_ = make_spring_constants(config_, params);
  if (!max_speed_valid_) max_speed_ = compute_max_speed();

  // Puts the particles back as they were before the frame: on a non-finite state and on any
  // exception (an allocation that fails halfway through a frame), so a failed step changes
  // nothing. The store's arrays keep their capacity, so this copies and does not allocate.
  auto roll_back = [&]() {
    count_ = count_before;
    store_.resize(count_);
    store_.restore(saved);
    max_speed_ = saved_max_speed;
    max_speed_valid_ = saved_max_speed_valid;
    max_acceleration_ = saved_max_acceleration;  // the force step limit reads it next step
    link_from_ = saved_link_from;
  };
  double remaining = frame_dt;
  double elapsed = 0.0;
  report.dt_min = std::numeric_limits<float>::max();
  try {
    while (remaining > 0.0 && report.substeps < params.max_substeps) {
      const float speed = std::max(max_speed_, scene.max_collider_speed);
      const double dt = landing_dt(controller_dt(limits, speed, max_acceleration_), remaining);
      const float dtf = static_cast<float>(dt);
      SubstepTime time;
      time.tau0 = static_cast<float>(elapsed);
      time.tau1 = static_cast<float>(elapsed + dt);
      time.s0 = static_cast<float>(elapsed / frame_dt);
      time.s1 = remaining <= dt ? 1.0f : static_cast<float>((elapsed + dt) / frame_dt);
      time.dt = dtf;
      fluid.dt = dtf;
      const uint32_t bad = config_.integrator == Integrator::Rk4 ? substep_rk4(fluid, scene, time, report)
                                                                 : substep_euler(fluid, scene, time, report);
      if (bad != kAllFinite) {
        roll_back();
        throw Error(Status::NonFinite, "the step produced non-finite values in the " + non_finite_.where +
                                           " of substep " + std::to_string(report.substeps + 1) + " (dt " +
                                           std::to_string(dtf) + " s" + above_stable_step(dtf, limits) +
                                           "): " + non_finite_.particles +
                                           "; the world was restored to its state before sph_world_step");
      }
      if (!scene.sinks.empty()) apply_sinks(scene, report);
      remaining -= dt;
      elapsed += dt;
      ++report.substeps;
      report.time_advanced += dt;
      report.dt_min = std::min(report.dt_min, dtf);
      report.dt_max = std::max(report.dt_max, dtf);
    }
  } catch (const Error& e) {
    if (e.status() != Status::NonFinite) roll_back();  // NonFinite has rolled back already
    throw;
  } catch (...) {
    roll_back();
    throw;
  }
  if (report.substeps == 0) report.dt_min = 0.0f;
  report.completed = remaining <= 0.0;
  report.max_speed = max_speed_;
  const auto t = Clock::now();
  summarize(report);
  report.stage_ms[kStageOther] += static_cast<float>(elapsed_ms(t));
  return report;
}

}  // namespace sph
