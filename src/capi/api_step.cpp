// SPDX-License-Identifier: MIT
// Stepping (with its budget and cancel) and statistics.
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <new>
#include <string>
#include <system_error>

#include "../core/byte_io.h"
#include "../core/checkpoint.h"
#include "../core/checkpoint_params.h"
#include "../core/rank_agreement.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "sph_cuda.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace sph {
namespace {
// A budget longer than a day is a mistake, not a bound.
constexpr double kMaxStepBudgetSeconds = 86400.0;

// frame_dt checked; on a distributed world (sph_mpi.h) inside one agreement, then compared between
// the ranks with their parameters (sph_world_set_params on each rank): a rank with a bad frame_dt
// used to return while the others waited for it in the frame's first collective call, and a rank
// with another frame or other parameters would take other substeps and wait alone in theirs. One
// agreement and two all-reduces of three int64 a frame. The scene's objects are compared by count
// (a rank with another collider or probe would meet the others' reductions with another size), the
// colliders also by pose and target.
void require_frame(const sph_world* world, float frame_dt) {
  const RankTransport* ranks = world->world->backend().rank_transport();
  if (!ranks) {
    require_positive(frame_dt, "frame_dt");
    return;
  }
  uint64_t params_hash = 0;
  agreed(*ranks, [&] {
    WorldLock::require_device_not_lost(world);  // (the lock left it to this agreement)
    require_positive(frame_dt, "frame_dt");
    ByteWriter w;
    write_params(w, world->world->params());  // (the checkpoints' canonical bytes)
    // And the world's definition as a checkpoint holds it, less its capacities (a rank's own).
    WorldConfig definition = world->world->config();
    definition.capacity = 0;
    definition.max_capacity = 0;
    write_config(w, definition);
    Fnv1a64 h;
    h.add(w.buffer().data(), w.size());
    params_hash = h.value();
  });
  // The scene's objects by kind: each rank holds the same (the loads, the sources' and the probes'
  // reductions have an element a collider, source or point).
  const World& w = *world->world;
  const uint64_t objects[5] = {w.colliders().size(), w.sources().size(), w.sinks().size(),
                               w.force_fields().size(), w.probes().size()};
  Fnv1a64 scene;
  scene.add(objects, sizeof objects);
  // And the colliders' poses and targets: each rank picks the step from the fastest collider
  // surface (SceneFrame::max_collider_speed, not reduced over the ranks), so a collider moved on
  // one rank alone would give the ranks other substeps.
  w.colliders().for_each([&](uint64_t, const Collider& c) {
    const auto add_pose = [&](const RigidTransform& t) {
      const float v[7] = {t.position.x, t.position.y, t.position.z, t.rotation.x,
                          t.rotation.y, t.rotation.z, t.rotation.w};
      scene.add(v, sizeof v);
    };
    add_pose(c.pose);
    const uint8_t targeted = c.target ? 1 : 0;
    scene.add(&targeted, 1);
    if (c.target) add_pose(*c.target);
  });
  const uint64_t scene_hash = scene.value();
  uint32_t dt_bits;
  std::memcpy(&dt_bits, &frame_dt, sizeof dt_bits);
  int64_t values[3] = {dt_bits, 0, 0};
  std::memcpy(&values[1], &params_hash, sizeof values[1]);
  std::memcpy(&values[2], &scene_hash, sizeof values[2]);
  bool same[3];
  compare_over_ranks(*ranks, values, 3, same);
  if (!same[0])
    throw Error(Status::InvalidArgument, "frame_dt: " + std::to_string(frame_dt) +
                                             " on this rank and another on another rank of the distributed "
                                             "world: every rank steps the same frame");
  if (!same[1])
    throw Error(Status::InvalidArgument,
                "world: its parameters (sph_world_set_params) or its definition (sph_world_def, capacities "
                "aside) differ between the ranks of the distributed world: every rank must set the same");
  if (!same[2])
    throw Error(Status::InvalidArgument,
                "world: its scene differs between the ranks of the distributed world (this rank has " +
                    std::to_string(objects[0]) + " colliders, " + std::to_string(objects[1]) + " sources, " +
                    std::to_string(objects[2]) + " sinks, " + std::to_string(objects[3]) + " force fields, " +
                    std::to_string(objects[4]) +
                    " probes; or a collider's pose or target differs): every rank must add and move the same "
                    "objects");
}

// One frame of a world whose lock the caller holds: true if it completed, false if its budget,
// a cancel or max_substeps stopped it; throws on failure (the world then as before the call).
bool run_frame(sph_world* world, float frame_dt, const FrameEnqueuedHook& enqueued = FrameEnqueuedHook{}) {
  const MemoryScope memory(&world->context->memory);  // (the step thread's or task's too)
  StepInterrupt interrupt;
  interrupt.cancel = &world->cancel_requested;
  if (world->step_budget_seconds > 0.0)
    interrupt.deadline =
        StepInterrupt::Clock::now() + std::chrono::duration_cast<StepInterrupt::Clock::duration>(
                                          std::chrono::duration<double>(world->step_budget_seconds));
  return marking_device_lost(world, [&] {
    const bool completed = world->world->step(frame_dt, interrupt, enqueued);
    if (world->world->last_report().interrupted) world->cancel_requested.store(0);
    return completed;
  });
}

// run_frame on the world's step thread or as a task: errors become an outcome for sph_world_step_wait.
StepOutcome run_frame_outcome(sph_world* world, float frame_dt,
                              const FrameEnqueuedHook& enqueued = FrameEnqueuedHook{}) noexcept {
  StepOutcome outcome;
  try {
    outcome.status = run_frame(world, frame_dt, enqueued) ? Status::Ok : Status::Incomplete;
  } catch (const Error& e) {
    outcome.status = e.status();
    outcome.message = e.what();
  } catch (const std::bad_alloc&) {
    outcome.status = Status::OutOfHostMemory;
    outcome.message = "a host allocation failed";
  } catch (const std::exception& e) {
    outcome.status = Status::Internal;
    outcome.message = e.what();
  } catch (...) {
    outcome.status = Status::Internal;
    outcome.message = "unknown internal exception";
  }
  return outcome;
}

// Starts `step` on the world's step thread, or as one task of `tasks` when it is a task system
// (the caller holds the world's lock).
void start_async_step(sph_world* world, std::function<StepOutcome()> step,
                      const TaskSystem& tasks = TaskSystem{}) {
  try {
    world->async_step.start(std::move(step), tasks);
  } catch (const std::system_error& e) {
    throw Error(Status::OutOfHostMemory, std::string("the step's thread could not be started: ") + e.what());
  }
}
}  // namespace
}  // namespace sph

extern "C" {

SPH_API sph_result SPH_CALL sph_world_step(sph_world* world, float frame_dt) {
  return sph::guarded("sph_world_step", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);  // (require_frame agrees on it)
    sph::require_frame(world, frame_dt);
    return sph::run_frame(world, frame_dt) ? SPH_OK : SPH_INCOMPLETE;
  });
}

SPH_API sph_result SPH_CALL sph_world_step_begin(sph_world* world, float frame_dt) {
  return sph::guarded("sph_world_step_begin", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    sph::require_positive(frame_dt, "frame_dt");
    // Its MPI calls would run on the step's thread, which MPI_Init's thread level does not allow.
    if (world->world->backend().distributed())
      throw Error(Status::Unsupported,
                  "world: a distributed world (sph_mpi.h) steps on the calling thread only; use "
                  "sph_mpi_world_step");
    // A CPU context with the engine's task system runs the frame as one task of it (the frame's
    // loops then enqueue from inside that task); a CUDA context ignores the task system.
    const sph_context& context = *world->context;
    const sph::TaskSystem tasks =
        context.backend == sph::BackendKind::Cpu ? context.cpu_tasks : sph::TaskSystem{};
    sph::start_async_step(
        world, [world, frame_dt] { return sph::run_frame_outcome(world, frame_dt); }, tasks);
    world->async_step.pending.store(true);
    lock.hand_over();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_step_begin_on_stream(sph_world* world, float frame_dt,
                                                                void* stream) {
  return sph::guarded("sph_cuda_world_step_begin_on_stream", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    sph::require_positive(frame_dt, "frame_dt");
    const sph::Backend& backend = world->world->backend();
    // As sph_world_step_begin: its MPI calls would run on the step's thread.
    if (backend.distributed())
      throw Error(Status::Unsupported,
                  "world: a distributed world (sph_mpi.h) steps on the calling thread only; use "
                  "sph_mpi_world_step");
    // Refuses a CPU world and a stream CUDA refuses.
    sph::marking_device_lost(world, [&] { backend.order_after_stream(stream); });
    auto enqueued = std::make_shared<sph::StepSignal>();
    sph::FrameEnqueuedHook hook = [&backend, stream, enqueued] {
      backend.order_stream_after(stream);
      enqueued->raise();
    };
    sph::start_async_step(world, [world, frame_dt, hook, enqueued] {
      sph::StepOutcome outcome = sph::run_frame_outcome(world, frame_dt, hook);
      enqueued->raise();  // a frame that failed before its work was enqueued
      return outcome;
    });
    world->async_step.pending.store(true);
    lock.hand_over();
    enqueued->wait();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_step_wait(sph_world* world) {
  return sph::guarded("sph_world_step_wait", sph::context_of(world), [&] {
    sph::require_world(world);
    switch (sph::try_collect_async_step(world)) {
      case sph::Collect::NotLive:
        throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
      case sph::Collect::Busy:
        throw Error(Status::WorldLocked,
                    "world: it is in use by another call (another thread may be waiting for its step)");
      case sph::Collect::NoStep:
        throw Error(Status::InvalidArgument,
                    "world: no step was begun (sph_world_step_begin) or it was already waited for");
      case sph::Collect::Taken:
        break;
    }
    sph::StepOutcome outcome = world->async_step.collect();
    sph::release_world(world);
    if (outcome.status == Status::Ok) return SPH_OK;
    if (outcome.status == Status::Incomplete) return SPH_INCOMPLETE;
    throw Error(outcome.status, outcome.message);
  });
}

SPH_API sph_result SPH_CALL sph_world_step_poll(const sph_world* world, sph_bool32* out_done) {
  return sph::guarded("sph_world_step_poll", sph::context_of(world), [&] {
    sph::require_world(world);
    if (!out_done) throw Error(Status::InvalidArgument, "out_done: is NULL");
    bool finished = false;
    switch (sph::poll_async_step(world, &finished)) {
      case sph::Collect::NotLive:
        throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
      case sph::Collect::Busy:
        throw Error(Status::WorldLocked, "world: it is in use by another call");
      case sph::Collect::NoStep:
        throw Error(Status::InvalidArgument,
                    "world: no step was begun (sph_world_step_begin) or it was already waited for");
      case sph::Collect::Taken:
        break;
    }
    *out_done = finished ? 1u : 0u;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_prepare(sph_world* world) {
  return sph::guarded("sph_world_prepare", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::MemoryScope memory(&world->context->memory);
    sph::marking_device_lost(world, [&] { world->world->prepare(); });
    return SPH_OK;
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
    s.density_error_largest = r.pressure_solve.largest_max;
    s.divergence_error_mean = r.divergence_solve.error_mean;
    s.divergence_error_max = r.divergence_solve.error_max;
    s.pressure_solves_capped = r.pressure_solve.capped;
    s.pressure_solves_guarded = r.pressure_solve.guarded;
    s.divergence_solves_capped = r.divergence_solve.capped;
    s.capacity = w.config().capacity;
    s.max_capacity = w.config().max_capacity;
    s.capacity_growths = w.capacity_growths();
    sph::write_output_struct(out, s, "out");
    return SPH_OK;
  });
}

}  // extern "C"
