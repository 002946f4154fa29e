// SPDX-License-Identifier: MIT
// Contexts: backend choice, device, CPU workers, CUDA tuning and logging.
#include <thread>
#include <type_traits>

#include "guard.h"
#include "handles.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

sph_context_def default_context_def() {
  sph_context_def d;
  std::memset(&d, 0, sizeof d);
  d.struct_size = sizeof d;
  d.backend = SPH_BACKEND_AUTO;
  d.device_ordinal = -1;
  return d;
}

// The CUDA tuning fields: the one place the library reads them (docs/cuda.md).
sph::CudaTuning cuda_tuning_from_def(const sph_context_def& d) {
  const uint32_t frames = sph::enum_bits(d.cuda_frames);
  if (frames != SPH_CUDA_FRAMES_GRAPH && frames != SPH_CUDA_FRAMES_STREAM)
    throw Error(Status::Unsupported,
                "def->cuda_frames: " + std::to_string(frames) + " is not an sph_cuda_frames value");
  const auto block = [](uint32_t value, const char* field) {
    const bool valid = value == 0 || (value >= 32 && value <= 1024 && (value & (value - 1)) == 0);
    if (!valid)
      throw Error(Status::InvalidArgument, std::string("def->") + field + ": " + std::to_string(value) +
                                               " threads per block; use 0 (default 128) or a power of two "
                                               "from 32 to 1024");
    return value;
  };
  const uint32_t lanes = d.cuda_particle_lanes;
  if (lanes != 0 && lanes != 1 && lanes != 2 && lanes != 4 && lanes != 8)
    throw Error(Status::InvalidArgument,
                "def->cuda_particle_lanes: " + std::to_string(lanes) +
                    " threads per particle; use 0 (the library's choice), 1, 2, 4 or 8");
  if (d.cuda_dfsph_masks != 0 && d.cuda_dfsph_masks != SPH_CUDA_DFSPH_MASKS_OFF &&
      d.cuda_dfsph_masks != SPH_CUDA_DFSPH_NEIGHBOR_LISTS)
    throw Error(Status::InvalidArgument,
                "def->cuda_dfsph_masks: " + std::to_string(d.cuda_dfsph_masks) +
                    " is none of 0 (masks, the default), SPH_CUDA_DFSPH_MASKS_OFF (1) and "
                    "SPH_CUDA_DFSPH_NEIGHBOR_LISTS (2)");
  sph::CudaTuning t;
  t.dfsph_masks = d.cuda_dfsph_masks != SPH_CUDA_DFSPH_MASKS_OFF;
  t.dfsph_lists = d.cuda_dfsph_masks == SPH_CUDA_DFSPH_NEIGHBOR_LISTS;
  t.stream_frames = frames == SPH_CUDA_FRAMES_STREAM;
  t.density_block = block(d.cuda_density_block, "cuda_density_block");
  t.force_block = block(d.cuda_force_block, "cuda_force_block");
  t.particle_lanes = lanes;
  return t;
}

static_assert(std::is_same<sph_task_fn, sph::TaskFn>::value, "the task hook types match core's");
static_assert(std::is_same<sph_enqueue_task_fn, sph::EnqueueTaskFn>::value,
              "the task hook types match core's");
static_assert(std::is_same<sph_finish_task_fn, sph::FinishTaskFn>::value, "the task hook types match core's");
static_assert(std::is_same<sph_alloc_fn, decltype(sph::HostMemoryHooks::alloc)>::value,
              "the allocator types match");
static_assert(std::is_same<sph_free_fn, decltype(sph::HostMemoryHooks::free)>::value,
              "the allocator types match");

// A hook without its other half would leave the library unable to wait for its tasks or to
// give memory back: refused, whichever half is missing.
sph::TaskSystem task_system_from_def(const sph_context_def& d) {
  if ((d.enqueue_task == nullptr) != (d.finish_task == nullptr))
    throw Error(Status::InvalidArgument, d.enqueue_task
                                             ? "def->finish_task: is NULL while enqueue_task is set; "
                                               "give both (the engine's task system) or neither"
                                             : "def->enqueue_task: is NULL while finish_task is set; "
                                               "give both (the engine's task system) or neither");
  if (!d.enqueue_task && d.task_user_context)
    throw Error(Status::InvalidArgument,
                "def->task_user_context: is set without enqueue_task and finish_task");
  sph::TaskSystem t;
  t.enqueue = d.enqueue_task;
  t.finish = d.finish_task;
  t.user_context = d.task_user_context;
  return t;
}

sph::HostMemoryHooks host_memory_from_def(const sph_context_def& d) {
  if ((d.alloc_fn == nullptr) != (d.free_fn == nullptr))
    throw Error(Status::InvalidArgument, d.alloc_fn
                                             ? "def->free_fn: is NULL while alloc_fn is set; give both "
                                               "(the engine's allocator) or neither"
                                             : "def->alloc_fn: is NULL while free_fn is set; give both "
                                               "(the engine's allocator) or neither");
  if (!d.alloc_fn && d.alloc_user_context)
    throw Error(Status::InvalidArgument, "def->alloc_user_context: is set without alloc_fn and free_fn");
  sph::HostMemoryHooks h;
  h.alloc = d.alloc_fn;
  h.free = d.free_fn;
  h.user_context = d.alloc_user_context;
  return h;
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_context_def_init_sized(sph_context_def* def, uint32_t size) {
  return sph::guarded("sph_context_def_init", nullptr, [&] {
    sph::require_init_size(def, size, "def");
    sph::write_user_struct(def, size, default_context_def());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_context_create(const sph_context_def* def, sph_context** out) {
  return sph::guarded("sph_context_create", nullptr, [&] {
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph_context_def d = sph::read_user_struct(def, "def");
    if (d.header_version != 0 && (d.header_version >> 22) != SPH_VERSION_MAJOR)
      throw Error(Status::VersionMismatch, "def->header_version: the caller's header is version " +
                                               std::to_string(d.header_version >> 22) +
                                               ".x but the library is " + std::to_string(SPH_VERSION_MAJOR) +
                                               ".x");
    const uint32_t backend = sph::enum_bits(d.backend);
    if (backend != SPH_BACKEND_AUTO && backend != SPH_BACKEND_CPU && backend != SPH_BACKEND_CUDA)
      throw Error(Status::Unsupported, "def->backend: " + std::to_string(static_cast<int32_t>(backend)) +
                                           " is not an sph_backend value");
    if (d.device_ordinal < -1)
      throw Error(Status::InvalidArgument,
                  "def->device_ordinal: must be -1 (default) or a device index, got " +
                      std::to_string(d.device_ordinal));
    if (d.cpu_worker_count > 4096)
      throw Error(Status::InvalidArgument,
                  "def->cpu_worker_count: " + std::to_string(d.cpu_worker_count) + " is more than 4096");
    const sph::CudaTuning cuda_tuning = cuda_tuning_from_def(d);
    const sph::BackendKind kind =
        sph::resolve_backend(static_cast<sph::BackendKind>(backend), d.device_ordinal);
    auto context = std::make_unique<sph_context>();
    context->backend = kind;
    context->device_ordinal = d.device_ordinal < 0 ? 0 : d.device_ordinal;
    const unsigned hw = std::thread::hardware_concurrency();
    context->cpu_workers = d.cpu_worker_count != 0 ? d.cpu_worker_count : (hw == 0 ? 1u : hw);
    context->cuda_tuning = cuda_tuning;
    context->log_fn = d.log_fn;
    context->log_user_data = d.log_user_data;
    context->cpu_tasks = task_system_from_def(d);
    context->memory.host = host_memory_from_def(d);
    sph::register_handle(context.get(), sph::HandleKind::Context);
    *out = context.release();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_context_destroy(sph_context* context) {
  if (!context) {
    sph::clear_last_error();
    return SPH_OK;
  }
  return sph::guarded("sph_context_destroy", nullptr, [&] {
    // What still uses the context is checked in the critical section that retires it.
    std::string why;
    const sph::Take take = sph::try_retire_context(context, &why);
    if (take == sph::Take::NotLive)
      throw Error(Status::InvalidHandle, "context: is not a live sph_context (destroyed or foreign pointer)");
    if (take == sph::Take::Busy) throw Error(Status::Busy, "context: " + why);
    delete context;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_context_get_backend(const sph_context* context, sph_backend* out_backend) {
  return sph::guarded("sph_context_get_backend", nullptr, [&] {
    const sph::ContextHold hold(context);
    if (!out_backend) throw Error(Status::InvalidArgument, "out_backend: is NULL");
    *out_backend = hold.get()->backend == sph::BackendKind::Cuda ? SPH_BACKEND_CUDA : SPH_BACKEND_CPU;
    return SPH_OK;
  });
}

}  // extern "C"
