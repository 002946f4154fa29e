// SPDX-License-Identifier: MIT
// Stepping (with its budget and cancel) and statistics.
#include <chrono>
#include <string>

#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace sph {
// A budget longer than a day is a mistake, not a bound.
constexpr double kMaxStepBudgetSeconds = 86400.0;
}  // namespace sph

extern "C" {

SPH_API sph_result SPH_CALL sph_world_step(sph_world* world, float frame_dt) {
  return sph::guarded("sph_world_step", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    sph::require_positive(frame_dt, "frame_dt");
    sph::StepInterrupt interrupt;
    interrupt.cancel = &world->cancel_requested;
    if (world->step_budget_seconds > 0.0)
      interrupt.deadline =
          sph::StepInterrupt::Clock::now() + std::chrono::duration_cast<sph::StepInterrupt::Clock::duration>(
                                                 std::chrono::duration<double>(world->step_budget_seconds));
    try {
      const bool completed = world->world->step(frame_dt, interrupt);
      if (world->world->last_report().interrupted) world->cancel_requested.store(0);
      return completed ? SPH_OK : SPH_INCOMPLETE;
    } catch (const Error& e) {
      if (e.status() == Status::DeviceLost) world->device_lost = true;
      throw;
    }
  });
}

SPH_API sph_result SPH_CALL sph_world_set_step_budget(sph_world* world, double max_seconds) {
  return sph::guarded("sph_world_set_step_budget", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!(max_seconds >= 0.0 && max_seconds <= sph::kMaxStepBudgetSeconds))
      sph::fail(Status::InvalidArgument,
                "max_seconds: must be in [0, 86400] (0: no budget), got " + std::to_string(max_seconds));
    world->step_budget_seconds = max_seconds;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_step_budget(const sph_world* world, double* out_seconds) {
  return sph::guarded("sph_world_get_step_budget", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_seconds) sph::fail(Status::InvalidArgument, "out_seconds: is NULL");
    *out_seconds = world->step_budget_seconds;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_cancel_step(sph_world* world) {
  return sph::guarded("sph_world_cancel_step", sph::context_of(world), [&] {
    if (!world) sph::fail(Status::InvalidHandle, "world: is NULL");
    if (!sph::raise_cancel(world))
      sph::fail(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_stats_init_sized(sph_stats* stats, uint32_t size) {
  return sph::init_user_struct("sph_stats_init", "stats", stats, size);
}

SPH_API sph_result SPH_CALL sph_world_get_stats(const sph_world* world, sph_stats* out) {
  return sph::guarded("sph_world_get_stats", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::World& w = *world->world;
    const sph::FrameReport& r = w.last_report();
    sph_stats s;
    std::memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    s.particle_count = w.particle_count();
    s.substeps = r.substeps;
    s.neighbors_max = r.neighbors_max;
    s.simulated_time = w.simulated_time();
    s.frame_time = static_cast<float>(r.time_advanced);
    s.dt_min = r.dt_min;
    s.dt_max = r.dt_max;
    s.max_speed = r.max_speed;
    s.density_min = r.density_min;
    s.density_mean = r.density_mean;
    s.density_max = r.density_max;
    s.neighbors_mean = r.neighbors_mean;
    for (int i = 0; i < SPH_STAGE_COUNT; ++i) s.stage_ms[i] = r.stage_ms[i];
    s.step_ms = w.last_step_ms();
    s.memory_bytes = w.backend().memory_bytes();
    s.pressure_iterations = r.pressure_solve.iterations;
    s.pressure_iterations_max = r.pressure_solve.iterations_max;
    s.divergence_iterations = r.divergence_solve.iterations;
    s.divergence_iterations_max = r.divergence_solve.iterations_max;
    s.density_error_mean = r.pressure_solve.error_mean;
    s.density_error_max = r.pressure_solve.error_max;
    s.divergence_error_mean = r.divergence_solve.error_mean;
    s.divergence_error_max = r.divergence_solve.error_max;
    s.pressure_solves_capped = r.pressure_solve.capped;
    s.divergence_solves_capped = r.divergence_solve.capped;
    sph::write_output_struct(out, s, "out");
    return SPH_OK;
  });
}

}  // extern "C"
