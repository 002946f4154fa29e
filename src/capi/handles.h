// SPDX-License-Identifier: MIT
// The opaque objects of the C ABI and the registry that tells a live handle from a dangling
// or foreign pointer in every build.
//
// Lifetimes: a handle's memory is freed only after it left the registry, and it leaves the
// registry only under the registry's mutex, in the same critical section that checks nobody
// uses it. Every call takes what it needs under that mutex too (the world's lock, a hold on a
// context, a reference to an SDF's asset), so a destroy racing another thread's call on the
// same object either waits its turn (WORLD_LOCKED, BUSY) or leaves the other call with
// memory it still owns; it never frees memory in use.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "../core/host_memory.h"
#include "../core/sdf_asset.h"
#include "../core/status.h"
#include "../core/task_system.h"
#include "../core/world.h"
#include "../factory/backend_factory.h"
#include "async_stepper.h"
#include "sph_c.h"

struct sph_context {
  sph::BackendKind backend;
  int device_ordinal;
  unsigned cpu_workers;
  sph::CudaTuning cuda_tuning;
  sph_log_fn log_fn;
  void* log_user_data;
  sph::TaskSystem cpu_tasks;  // the engine's task system (none: OpenMP)
  // The engine's allocators (none: the heap, cudaMalloc); the context outlives every world and
  // SDF asset whose memory came from them.
  sph::MemoryHooks memory;
  // What keeps the context alive; changed and read only under the registry's mutex.
  uint32_t world_count = 0;    // worlds created on it
  uint32_t sdf_count = 0;      // SDF assets created on it
  uint32_t held_by_calls = 0;  // calls in flight that use it (ContextHold)
  // Worlds made on it by sph_world_create and sph_mpi_world_create (not by a load): the n-th
  // world's ids carry world tag ((n - 1) mod 65535) + 1 (next_world_tag), so that one program's
  // calls give the same ids, and the same checkpoint bytes, run to run. Tag 0 is left to worlds
  // loaded from checkpoints of format 14 or older.
  std::atomic<uint32_t> worlds_made{0};
};

struct sph_sdf {
  sph_context* context;
  std::shared_ptr<sph::SdfAsset> asset;
};

struct sph_world {
  sph_context* context;
  std::unique_ptr<sph::World> world;
  std::atomic<bool> busy{false};     // taken under the registry's mutex (WorldLock, destroy)
  bool device_lost = false;          // read and written only while busy is held
  double step_budget_seconds = 0.0;  // 0: none (sph_world_set_step_budget); read while busy is held
  // Raised by sph_world_cancel_step from any thread (under the registry's mutex, so never on a
  // freed world), lowered by the step that it stopped.
  std::atomic<uint32_t> cancel_requested{0};
  // sph_world_step_begin's thread; declared last, so it stops before the world goes away.
  sph::AsyncStepper async_step;
};

namespace sph {

enum class HandleKind { Context, World, Sdf };

void register_handle(const void* handle, HandleKind kind);
bool is_live_handle(const void* handle, HandleKind kind);
uint32_t live_handle_count();

// Where a failing call reports: the context's log callback, copied under the registry's
// mutex when the call starts, so reporting never touches a context or world that another
// thread destroyed meanwhile.
struct LogTarget {
  sph_log_fn fn = nullptr;
  void* user_data = nullptr;
  const MemoryHooks* memory = nullptr;  // the context's allocators, current for the call (guarded)
  LogTarget() = default;
  LogTarget(std::nullptr_t) {}            // NOLINT: guarded(name, nullptr, ...) for calls without a context
  LogTarget(const sph_context* context);  // NOLINT: a live context's callback, else none
};
LogTarget log_target_of(const sph_world* world);
LogTarget log_target_of(const sph_sdf* sdf);

// Takes a world for one call: under the registry's mutex, the handle is live and its busy
// flag was free. Results: Locked (the caller owns the world until unlock_world), NotLive, Busy.
enum class Take { Taken, NotLive, Busy };
Take try_take_world(const sph_world* world);
void release_world(const sph_world* world);
// Raises a live world's cancel flag whether or not another call holds it; false if not live.
bool raise_cancel(const sph_world* world);
// For sph_world_step_wait: under the registry's mutex, a live world whose asynchronous step is
// pending passes to the caller (Taken: the caller now holds the world's lock the step held, and
// no other waiter can take it); Busy if another call holds the world; NoStep if nothing does.
enum class Collect { Taken, NotLive, Busy, NoStep };
Collect try_collect_async_step(sph_world* world);
// For sph_world_step_poll: as above without taking anything; *finished says whether the pending
// step has ended.
Collect poll_async_step(const sph_world* world, bool* finished);
// Takes a world for destruction: as try_take_world, and on Taken the handle has left the
// registry (and its context's count) in the same critical section; the caller deletes it.
Take try_retire_world(sph_world* world);

// Keeps a context alive while a call uses it (creating a world or SDF on it, copying through
// its device): sph_context_destroy answers BUSY meanwhile. Throws InvalidHandle for a NULL or
// dead context (named `name`).
class ContextHold {
 public:
  ContextHold(const sph_context* context, const char* name = "context");
  // Adopts a hold the registry already counted (use_sdf takes it with the SDF's asset).
  struct Adopt {};
  ContextHold(sph_context* held, Adopt) : context_(held) {}
  ~ContextHold();
  ContextHold(ContextHold&& other) noexcept : context_(other.context_) { other.context_ = nullptr; }
  ContextHold(const ContextHold&) = delete;
  ContextHold& operator=(const ContextHold&) = delete;
  ContextHold& operator=(ContextHold&&) = delete;
  sph_context* get() const { return context_; }

 private:
  sph_context* context_;
};

// Publishes a new object made on a held context: registers the handle and counts it on the
// context in one critical section. Returns the handle (ownership passes to the caller's caller).
sph_world* publish_world(std::unique_ptr<sph_world> world);
// A new world from a def (validated here; Errors name its fields "def->..."), not yet published.
std::unique_ptr<sph_world> make_world(sph_context* context, const sph_world_def& def);
// The world tag of the next world made on `context` (counts it): 1, 2, ... 65535, 1, ...
uint16_t next_world_tag(sph_context* context);
sph_sdf* publish_sdf(std::unique_ptr<sph_sdf> sdf);

// Takes a context for destruction: Taken means it left the registry and the caller deletes
// it; otherwise *why says what still uses it (Busy) or that it is not live (NotLive).
Take try_retire_context(sph_context* context, std::string* why);
// Replaces a live context's device allocator while nothing uses the context (no world, no SDF
// asset, no call holding it); otherwise Busy with *why, or NotLive.
Take try_set_device_memory(sph_context* context, const DeviceMemoryHooks& hooks, std::string* why);
// Takes an SDF handle out of the registry (its context's count drops with it); the caller
// deletes it. Calls in flight on it keep their own reference to the asset and hold the context.
bool try_retire_sdf(sph_sdf* sdf);

// What one call uses of an SDF handle: its asset and a hold on its context, taken under the
// registry's mutex, so a concurrent sph_sdf_destroy frees neither. Throws InvalidHandle for a
// NULL (`null_status` lets a caller report NULL as InvalidArgument) or dead handle.
struct SdfUse {
  ContextHold context;
  std::shared_ptr<SdfAsset> asset;
};
SdfUse use_sdf(const sph_sdf* sdf, const std::string& name, Status null_status = Status::InvalidHandle);

}  // namespace sph
