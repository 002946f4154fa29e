// SPDX-License-Identifier: MIT
// The CPU backend's frame: adaptive substeps until the frame time is reached, sinks after each,
// and the rollback that puts the particles back when a substep fails (the twin of
// cuda/frame_loop.cu).
#include <algorithm>

#include "../core/rank_agreement.h"
#include "../core/scene_frame.h"
#include "../core/status.h"
#include "../core/substep_clock.h"
#include "cpu_backend_impl.h"

namespace sph {

void CpuBackend::bind_boundary_maps(const FluidConstants& fluid, SceneFrame& scene) {
  collider_views_.clear();
  if (!boundary_) return;
  boundary_maps_.begin_frame();
  for (ColliderFrame& c : scene.colliders) {
    const float level = BoundaryDensity::map_level(fluid.methods.boundary, c.view.sign);
    c.view.boundary_map = boundary_maps_.bind(*c.sdf, config_.kernel_radius, level, workers_);
    collider_views_.push_back(c.view);
  }
  boundary_maps_.end_frame();
}

void CpuBackend::prepare_scene(const SceneFrame& scene_in, const RuntimeParams& params) {
  if (!boundary_) return;
  SceneFrame scene = scene_in;
  bind_scene_views(scene, [](const SdfAsset& a) { return a.host_view(); });
  bind_boundary_maps(make_fluid_constants(config_, params), scene);
}

FrameReport CpuBackend::step_scene_frame(double frame_dt, const RuntimeParams& params,
                                         const SceneFrame& scene_in) {
  FrameReport report;
  FluidConstants fluid = make_fluid_constants(config_, params);
  // The conjugate gradients' density solve moves velocities outside dfsph_correct (its search
  // directions and its own contact holds) and keeps only the positive part of what it applied, so
  // the loads' sums (collider_loads.h) would not be the momentum it gave the walls.
  if (config_.solver == Solver::Dfsph && loads_on() &&
      fluid.methods.dfsph.linear_solver == kDfsphConjugateGradients)
    throw Error(Status::Unsupported,
                "step: SPH_FEATURE_COLLIDER_LOADS with DFSPH's conjugate gradients solve "
                "(sph_dfsph_params.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS) is not supported yet; the "
                "loads follow the Jacobi solve's velocity updates, use SPH_DFSPH_JACOBI");
  const StepLimits limits = make_step_limits(config_, params);
  frame_limits_ = limits;
  fluid_height_ = 0.0f;
  SceneFrame scene = scene_in;
  bind_scene_views(scene, [](const SdfAsset& a) { return a.host_view(); });
  bind_boundary_maps(fluid, scene);
  begin_loads(scene);
  begin_probes(scene);
  report.removed_by_sink.assign(scene.sinks.size(), 0u);
  // Room for the loads' and probes' sums copied into the report after the frame, taken now: once
  // the particles have moved nothing may allocate (the copy has no rollback behind it; the CUDA
  // backend sizes them before its frame too).
  report.collider_loads.reserve(load_sums_.size());
  report.probes.reserve(probe_sums_.size());
  const uint32_t count_before = count_;
  const auto saved = store_.snapshot();
  const float saved_max_speed = max_speed_;
  const bool saved_max_speed_valid = max_speed_valid_;
  const float saved_max_acceleration = max_acceleration_;
  spring_constants_ = fluid.methods.springs;
  if (!max_speed_valid_) max_speed_ = compute_max_speed();
  // DFSPH's depth limit: H of the first step from the frame's positions, of each next one from the
  // positions a substep leaves before the sinks run (as the CUDA backend measures it, and as the
  // max speed is taken); a distributed world's ranks reduce it over the world with the maxima.
  if (rank_)
    halo_begin_frame();
  else
    measure_fluid_height();

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
  };
  SubstepClock clock;
  start_clock(clock, frame_dt);
  DfsphTallies tallies;
  try {
    while (clock_running(clock, params.stepping.max_substeps)) {
      // A distributed world's ranks stop together: a cancel or budget seen by any rank stops all.
      if (rank_ ? rank_->any(scene.interrupt.requested()) : scene.interrupt.requested()) {
        report.interrupted = true;
        break;
      }
      pick_next_step(clock, frame_dt, limits, std::max(max_speed_, scene.max_collider_speed),
                     max_acceleration_, fluid_height_);
      fluid.dt = clock.dt_float;
      uint32_t bad =
          config_.solver == Solver::Dfsph         ? substep_dfsph(fluid, scene, clock.time, report, tallies)
          : config_.integrator == Integrator::Rk4 ? substep_rk4(fluid, scene, clock.time, report)
                                                  : substep_euler(fluid, scene, clock.time, report);
      if (rank_)
        bad = halo_end_substep(bad);
      else if (bad == kAllFinite)
        measure_fluid_height();
      if (bad != kAllFinite) {
        roll_back();
        non_finite_.substep = clock.substeps + 1;
        non_finite_.dt = clock.dt_float;
        // (Every rank of a distributed world has found it in halo_end_substep's agreement.)
        if (rank_) throw AgreedRankFailure(Status::NonFinite, non_finite_message(non_finite_, limits));
        throw Error(Status::NonFinite, non_finite_message(non_finite_, limits));
      }
      if (!scene.sinks.empty()) apply_sinks(scene, report);
      advance_clock(clock);
    }
    // Every rank reads the world's loads: summed over the ranks inside the frame, so that a rank
    // whose part of the sum fails (an allocation) rolls back with the others, which meet it at the
    // exchange's own agreement or at the one below (it was after them, outside the rollback: the
    // ranks' worlds parted, or waited for each other forever; mpi_rank_failure's loads case).
    if (rank_ && !load_sums_.empty()) rank_->sum_loads(load_sums_.data(), load_sums_.size());
    // The frame's end: a rank that failed after the last substep's agreement (its sinks, the loads'
    // sum) fails every rank; nothing after this can fail.
    if (rank_) rank_->agree();
  } catch (const Error& e) {
    if (e.status() != Status::NonFinite) roll_back();  // NonFinite has rolled back already
    throw;
  } catch (...) {
    roll_back();
    throw;
  }
  report_clock(clock, report);
  report.pressure_solve = finish_solve(tallies.pressure);
  report.divergence_solve = finish_solve(tallies.divergence);
  report.max_speed = max_speed_;
  report.collider_loads = load_sums_;
  report.probes = probe_sums_;
  const auto t = stage_start();
  summarize(report);
  end_stage(report, kStageOther, t);
  return report;
}

}  // namespace sph
