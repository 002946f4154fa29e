// SPDX-License-Identifier: MIT
// Every exported function runs its body through guarded(): it clears the thread's last error,
// makes the context's allocators current (core/host_memory.h), turns exceptions into result
// codes and messages, tells the context's log callback, and makes sure nothing escapes across
// the C boundary.
#pragma once

#include <cstdio>
#include <new>
#include <string>

#include "../core/status.h"
#include "handles.h"
#include "last_error.h"
#include "sph_c.h"

namespace sph {

inline sph_result to_result(Status s) { return static_cast<sph_result>(static_cast<int>(s)); }

inline sph_result fail(Status status, const std::string& message) { throw Error(status, message); }

// Whether this thread is inside a log callback now. One flag for warnings and failures alike:
// while the callback runs, nothing the library reports on this thread reaches a callback again
// (no recursion, one level deep at most); the calls it makes still return their codes and set
// the thread's last error as usual.
inline bool& inside_log_callback() {
  static thread_local bool inside = false;
  return inside;
}

// Calls the log callback with the flag above set for its duration. A callback must return
// normally (sph_log_fn); one written in C++ that throws anyway has its exception dropped here,
// so that it cannot leave the flag set (silencing the thread's later reports) nor reach
// guarded()'s noexcept boundary from inside a catch handler (std::terminate).
inline void call_log_callback(const LogTarget& log, sph_log_level level, sph_result code,
                              const char* message) noexcept {
  struct InsideScope {
    InsideScope() { inside_log_callback() = true; }
    ~InsideScope() { inside_log_callback() = false; }
  } inside;
  try {
    log.fn(log.user_data, level, code, message);
  } catch (...) {
  }
}

// Sets the thread's last error and tells the log callback. The callback may call into the
// library (sph_world_get_stats, say), which clears or replaces the thread's last error, so the
// message is set again after it returns: the failing call's message is what its caller reads.
inline void report_failure(const LogTarget& log, const char* function, sph_result code, const char* what) {
  char message[1024];
  std::snprintf(message, sizeof message, "%s: %s", function, what);
  set_last_error(message);
  if (log.fn && !inside_log_callback()) {
    call_log_callback(log, SPH_LOG_ERROR, code, message);
    set_last_error(message);
  }
}

// Tells the log callback of a successful call's warning (SPH_LOG_WARNING, code SPH_OK). The
// thread's last error stays clear: the call succeeded, whatever the callback called meanwhile.
inline void report_warning(const LogTarget& log, const char* function, const char* what) {
  if (!log.fn || inside_log_callback()) return;
  char message[1024];
  std::snprintf(message, sizeof message, "%s: %s", function, what);
  call_log_callback(log, SPH_LOG_WARNING, SPH_OK, message);
  clear_last_error();
}

template <class Body>
sph_result guarded(const char* function, const LogTarget& log, Body&& body) noexcept {
  clear_last_error();
  const MemoryScope memory(log.memory);
  try {
    return body();
  } catch (const Error& e) {
    const sph_result code = to_result(e.status());
    report_failure(log, function, code, e.what());
    return code;
  } catch (const std::bad_alloc&) {
    report_failure(log, function, SPH_ERROR_OUT_OF_HOST_MEMORY, "a host allocation failed");
    return SPH_ERROR_OUT_OF_HOST_MEMORY;
  } catch (const std::exception& e) {
    report_failure(log, function, SPH_ERROR_INTERNAL, e.what());
    return SPH_ERROR_INTERNAL;
  } catch (...) {
    report_failure(log, function, SPH_ERROR_INTERNAL, "unknown internal exception");
    return SPH_ERROR_INTERNAL;
  }
}

// Holds a world for the duration of one call; a second concurrent call gets WORLD_LOCKED.
// Every call that takes a world, const ones included, holds it: the lock is taken under the
// handle registry's mutex, so a concurrent sph_world_destroy cannot free the world meanwhile
// (destroy takes the same lock before the world leaves the registry).
//
// A collective call on a distributed world (sph_mpi.h) takes it with kAgreeDeviceLoss: a rank whose
// device was lost must not return before the others reach their first agreement, where they would
// wait for it in MPI; the call throws require_device_not_lost's error inside that agreement instead.
class WorldLock {
 public:
  enum DeviceLoss { kThrowDeviceLoss, kAgreeDeviceLoss };
  explicit WorldLock(const sph_world* world, DeviceLoss device_loss = kThrowDeviceLoss) : world_(world) {
    if (!world_) throw Error(Status::InvalidHandle, "world: is NULL");
    const Take take = try_take_world(world_);
    if (take == Take::NotLive)
      throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
    if (take == Take::Busy)
      throw Error(Status::WorldLocked,
                  "world: it is in use by another call (a world is used from one thread at a time)");
    if (world_->device_lost && !(device_loss == kAgreeDeviceLoss && distributed(world_))) {
      release_world(world_);
      throw_device_lost();
    }
  }
  // Inside a distributed collective call's first agreement (kAgreeDeviceLoss).
  static void require_device_not_lost(const sph_world* world) {
    if (world->device_lost) throw_device_lost();
  }
  ~WorldLock() {
    if (world_) release_world(world_);
  }
  // Hands the lock to an asynchronous step, which keeps it until sph_world_step_wait.
  void hand_over() { world_ = nullptr; }
  WorldLock(const WorldLock&) = delete;
  WorldLock& operator=(const WorldLock&) = delete;

 private:
  [[noreturn]] static void throw_device_lost() {
    throw Error(Status::DeviceLost, "world: its device was lost after a sticky device error; destroy it");
  }
  static bool distributed(const sph_world* world) { return world->world->backend().distributed(); }
  const sph_world* world_;
};

// Runs body() on a world whose lock the caller holds and passes on whatever it throws; a
// DEVICE_LOST error first marks the world lost, so that every later call on it answers
// DEVICE_LOST (WorldLock) until it is destroyed.
template <class Body>
auto marking_device_lost(const sph_world* world, Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const Error& e) {
    if (e.status() == Status::DeviceLost) const_cast<sph_world*>(world)->device_lost = true;
    throw;
  }
}

// Validates a world handle without touching the world's memory (WorldLock checks the rest:
// it must follow before the world is used).
inline void require_world(const sph_world* world) {
  if (!world) throw Error(Status::InvalidHandle, "world: is NULL");
  if (!is_live_handle(world, HandleKind::World))
    throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
}

inline LogTarget context_of(const sph_world* world) { return log_target_of(world); }

// SPH_ATTRIBUTE_USER needs SPH_FEATURE_USER_ATTRIBUTE (the caller holds the world's lock).
inline void require_user_attribute(const sph_world* world) {
  if (!(world->world->config().features & kFeatureUserAttribute))
    throw Error(Status::FeatureDisabled,
                "world: SPH_FEATURE_USER_ATTRIBUTE is not enabled in its sph_world_def (SPH_ATTRIBUTE_USER)");
}

}  // namespace sph
