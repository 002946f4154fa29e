// SPDX-License-Identifier: MIT
// Checkpoints: saving a world to memory or a file (atomically), loading one into a new world,
// restoring one into an existing world. The format itself lives in src/core/checkpoint*.
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "../core/checkpoint.h"
#include "../core/checkpoint_format.h"
#include "checkpoint_files.h"
#include "dfsph_solver_check.h"
#include "guard.h"
#include "handles.h"

using sph::Error;
using sph::Status;

namespace {

sph::HostVector<uint8_t> save_world(const sph_world* world) {
  sph::CheckpointOrigin origin;
  origin.backend = static_cast<uint32_t>(world->context->backend);
  origin.library_version = SPH_VERSION;
  try {
    return sph::write_checkpoint(*world->world, origin);
  } catch (const Error& e) {
    if (e.status() == Status::DeviceLost) const_cast<sph_world*>(world)->device_lost = true;
    throw;
  }
}

std::unique_ptr<sph::World> load_world(sph_context* context, const void* data, uint64_t size) {
  if (!data) throw Error(Status::InvalidArgument, "data: is NULL");
  if (size > SIZE_MAX) throw Error(Status::InvalidArgument, "size: does not fit in memory");
  std::unique_ptr<sph::World> world = sph::read_checkpoint(
      static_cast<const uint8_t*>(data), static_cast<size_t>(size),
      [context](const sph::WorldConfig& config) {
        return sph::make_backend(context->backend, config, context->device_ordinal, context->cpu_workers,
                                 context->cpu_tasks, context->cuda_tuning);
      });
  // A checkpoint's DFSPH parameters that this context cannot run (the state built beside any
  // world it would replace, so nothing has changed).
  sph::require_supported_dfsph_solver(*world, world->params(), "checkpoint: sph_dfsph_params.linear_solver");
  return world;
}

// `hold` keeps the context alive from the start of the call to the new world's registration.
sph_result publish(const sph::ContextHold& hold, std::unique_ptr<sph::World> loaded, sph_world** out) {
  auto world = std::make_unique<sph_world>();
  world->context = hold.get();
  world->world = std::move(loaded);
  *out = sph::publish_world(std::move(world));
  return SPH_OK;
}

void require_path(const char* path) {
  if (!path) throw Error(Status::InvalidArgument, "path: is NULL");
  if (!*path) throw Error(Status::InvalidArgument, "path: is empty");
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_world_save(const sph_world* world, void* buffer, uint64_t buffer_size,
                                           uint64_t* out_size) {
  return sph::guarded("sph_world_save", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_size) throw Error(Status::InvalidArgument, "out_size: is NULL");
    if (!buffer && buffer_size != 0)
      throw Error(Status::InvalidArgument, "buffer: is NULL but buffer_size is " +
                                               std::to_string(buffer_size) + " (pass 0 to ask the size)");
    const sph::HostVector<uint8_t> bytes = save_world(world);
    *out_size = bytes.size();
    if (!buffer) return SPH_OK;
    if (buffer_size < bytes.size())
      throw Error(Status::BufferTooSmall, "buffer_size: " + std::to_string(buffer_size) +
                                              " bytes; the checkpoint needs " + std::to_string(bytes.size()) +
                                              " (in *out_size)");
    std::memcpy(buffer, bytes.data(), bytes.size());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_save_file(const sph_world* world, const char* path) {
  return sph::guarded("sph_world_save_file", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_path(path);
    sph::write_file_atomically(path, save_world(world));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_load(sph_context* context, const void* data, uint64_t size,
                                           sph_world** out) {
  return sph::guarded("sph_world_load", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    return publish(hold, load_world(hold.get(), data, size), out);
  });
}

SPH_API sph_result SPH_CALL sph_world_load_file(sph_context* context, const char* path, sph_world** out) {
  return sph::guarded("sph_world_load_file", context, [&] {
    const sph::ContextHold hold(context);
    require_path(path);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph::HostVector<uint8_t> bytes = sph::read_checkpoint_file(path);
    try {
      static const uint8_t nothing = 0;  // an empty file is a truncated checkpoint, not NULL data
      return publish(hold, load_world(hold.get(), bytes.empty() ? &nothing : bytes.data(), bytes.size()),
                     out);
    } catch (const Error& e) {
      throw Error(e.status(), std::string(e.what()) + " (file '" + path + "')");
    }
  });
}

SPH_API sph_result SPH_CALL sph_world_restore(sph_world* world, const void* data, uint64_t size) {
  return sph::guarded("sph_world_restore", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (world->world->backend().distributed())
      throw Error(Status::Unsupported,
                  "world: a distributed world restores from its ranks' checkpoints and their manifest: "
                  "sph_mpi_world_restore_file on every rank (sph_mpi.h)");
    // The new state is built whole beside the old one, then swapped in.
    std::unique_ptr<sph::World> loaded = load_world(world->context, data, size);
    // A file of format 6 or later carries its probes; an older one has none, and the world
    // keeps its own (the rule before probes were in checkpoints).
    if (sph::checkpoint::format_version_of(data) < sph::checkpoint::kFirstProbeVersion)
      loaded->adopt_probes(*world->world);
    // The world takes the checkpoint's world tag, and never issues again an id it issued before
    // (one issued after the save included).
    loaded->keep_issued_ids(*world->world);
    // Objects whose assets the caller has not changed since the save keep the caller's assets
    // (not the checkpoint's copies), and the maps computed from them.
    loaded->keep_caller_assets(*world->world);
    loaded->backend().continue_data_epoch(world->world->backend());
    loaded->backend().adopt_asset_caches(world->world->backend());
    world->world.swap(loaded);
    return SPH_OK;
  });
}

}  // extern "C"
