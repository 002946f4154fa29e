// SPDX-License-Identifier: MIT
#include "handles.h"

#include <mutex>
#include <unordered_map>

namespace sph {
namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}

std::unordered_map<const void*, HandleKind>& registry() {
  static std::unordered_map<const void*, HandleKind> r;
  return r;
}

// With the registry's mutex held.
bool live_locked(const void* handle, HandleKind kind) {
  const auto it = registry().find(handle);
  return it != registry().end() && it->second == kind;
}

}  // namespace

void register_handle(const void* handle, HandleKind kind) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[handle] = kind;
}

bool is_live_handle(const void* handle, HandleKind kind) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  return live_locked(handle, kind);
}

uint32_t live_handle_count() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  return static_cast<uint32_t>(registry().size());
}

LogTarget::LogTarget(const sph_context* context) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (context && live_locked(context, HandleKind::Context)) {
    fn = context->log_fn;
    user_data = context->log_user_data;
    memory = &context->memory;
  }
}

LogTarget log_target_of(const sph_world* world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  LogTarget target;
  // A live world's context is alive: it counts the world.
  if (world && live_locked(world, HandleKind::World)) {
    target.fn = world->context->log_fn;
    target.user_data = world->context->log_user_data;
    target.memory = &world->context->memory;
  }
  return target;
}

LogTarget log_target_of(const sph_sdf* sdf) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  LogTarget target;
  if (sdf && live_locked(sdf, HandleKind::Sdf)) {
    target.fn = sdf->context->log_fn;
    target.user_data = sdf->context->log_user_data;
    target.memory = &sdf->context->memory;
  }
  return target;
}

Take try_take_world(const sph_world* world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!world || !live_locked(world, HandleKind::World)) return Take::NotLive;
  bool expected = false;
  return const_cast<sph_world*>(world)->busy.compare_exchange_strong(expected, true) ? Take::Taken
                                                                                     : Take::Busy;
}

void release_world(const sph_world* world) { const_cast<sph_world*>(world)->busy.store(false); }

bool raise_cancel(const sph_world* world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!world || !live_locked(world, HandleKind::World)) return false;
  const_cast<sph_world*>(world)->cancel_requested.store(1);
  return true;
}

Collect try_collect_async_step(sph_world* world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!world || !live_locked(world, HandleKind::World)) return Collect::NotLive;
  if (world->async_step.pending.exchange(false)) return Collect::Taken;
  return world->busy.load() ? Collect::Busy : Collect::NoStep;
}

Collect poll_async_step(const sph_world* world, bool* finished) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!world || !live_locked(world, HandleKind::World)) return Collect::NotLive;
  if (world->async_step.pending.load()) {
    *finished = world->async_step.finished();
    return Collect::Taken;
  }
  return world->busy.load() ? Collect::Busy : Collect::NoStep;
}

Take try_retire_world(sph_world* world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!world || !live_locked(world, HandleKind::World)) return Take::NotLive;
  bool expected = false;
  if (!world->busy.compare_exchange_strong(expected, true)) return Take::Busy;
  registry().erase(world);
  --world->context->world_count;
  return Take::Taken;
}

ContextHold::ContextHold(const sph_context* context, const char* name) : context_(nullptr) {
  if (!context) throw Error(Status::InvalidHandle, std::string(name) + ": is NULL");
  {
    std::lock_guard<std::mutex> lock(registry_mutex());
    if (live_locked(context, HandleKind::Context)) {
      context_ = const_cast<sph_context*>(context);
      ++context_->held_by_calls;
    }
  }
  if (!context_)
    throw Error(Status::InvalidHandle,
                std::string(name) + ": is not a live sph_context (destroyed or foreign pointer)");
}

ContextHold::~ContextHold() {
  if (!context_) return;
  std::lock_guard<std::mutex> lock(registry_mutex());
  --context_->held_by_calls;
}

sph_world* publish_world(std::unique_ptr<sph_world> world) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[world.get()] = HandleKind::World;
  ++world->context->world_count;
  return world.release();
}

sph_sdf* publish_sdf(std::unique_ptr<sph_sdf> sdf) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[sdf.get()] = HandleKind::Sdf;
  ++sdf->context->sdf_count;
  return sdf.release();
}

Take try_retire_context(sph_context* context, std::string* why) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!context || !live_locked(context, HandleKind::Context)) return Take::NotLive;
  // Built before anything is erased: to_string may throw, and then nothing has changed.
  if (context->world_count != 0) {
    *why =
        std::to_string(context->world_count) + " world(s) created on it are still alive; destroy them first";
    return Take::Busy;
  }
  if (context->sdf_count != 0) {
    *why = std::to_string(context->sdf_count) +
           " SDF asset(s) created on it are still alive; destroy them first";
    return Take::Busy;
  }
  if (context->held_by_calls != 0) {
    *why = "another thread's call is using it (creating a world or an SDF asset on it)";
    return Take::Busy;
  }
  registry().erase(context);
  return Take::Taken;
}

Take try_set_device_memory(sph_context* context, const DeviceMemoryHooks& hooks, std::string* why) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!context || !live_locked(context, HandleKind::Context)) return Take::NotLive;
  if (context->world_count != 0 || context->sdf_count != 0 || context->held_by_calls != 0) {
    *why = std::to_string(context->world_count) + " world(s) and " + std::to_string(context->sdf_count) +
           " SDF asset(s) use it" +
           (context->held_by_calls != 0 ? ", and another thread's call holds it" : "") +
           "; set the allocator before creating any";
    return Take::Busy;
  }
  context->memory.device = hooks;
  return Take::Taken;
}

bool try_retire_sdf(sph_sdf* sdf) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  if (!sdf || !live_locked(sdf, HandleKind::Sdf)) return false;
  registry().erase(sdf);
  --sdf->context->sdf_count;
  return true;
}

SdfUse use_sdf(const sph_sdf* sdf, const std::string& name, Status null_status) {
  if (!sdf) throw Error(null_status, name + ": is NULL");
  sph_context* context = nullptr;
  std::shared_ptr<SdfAsset> asset;
  {
    std::lock_guard<std::mutex> lock(registry_mutex());
    if (live_locked(sdf, HandleKind::Sdf)) {
      context = sdf->context;
      asset = sdf->asset;
      ++context->held_by_calls;
    }
  }
  if (!context)
    throw Error(Status::InvalidHandle, name + ": is not a live sph_sdf (destroyed or foreign pointer)");
  return SdfUse{ContextHold(context, ContextHold::Adopt{}), std::move(asset)};
}

}  // namespace sph
