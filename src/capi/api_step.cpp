// SPDX-License-Identifier: MIT
// Stepping and statistics.
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

extern "C" {

SPH_API sph_result SPH_CALL sph_world_step(sph_world* world, float frame_dt) {
  return sph::guarded("sph_world_step", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    sph::require_positive(frame_dt, "frame_dt");
    try {
      return world->world->step(frame_dt) ? SPH_OK : SPH_INCOMPLETE;
    } catch (const Error& e) {
      if (e.status() == Status::DeviceLost) world->device_lost = true;
      throw;
    }
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
    sph::write_output_struct(out, s, "out");
    return SPH_OK;
  });
}

}  // extern "C"
