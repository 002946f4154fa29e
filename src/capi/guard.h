// Every exported function runs its body through guarded(): it clears the thread's last error,
// turns exceptions into result codes and messages, tells the context's log callback, and
// makes sure nothing escapes across the C boundary.
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

inline void report_failure(const sph_context* context, const char* function, sph_result code,
                           const char* what) {
  char message[1024];
  std::snprintf(message, sizeof message, "%s: %s", function, what);
  set_last_error(message);
  if (context && context->log_fn) context->log_fn(context->log_user_data, SPH_LOG_ERROR, code, message);
}

template <class Body>
sph_result guarded(const char* function, const sph_context* context, Body&& body) noexcept {
  clear_last_error();
  try {
    return body();
  } catch (const Error& e) {
    const sph_result code = to_result(e.status());
    report_failure(context, function, code, e.what());
    return code;
  } catch (const std::bad_alloc&) {
    report_failure(context, function, SPH_ERROR_OUT_OF_HOST_MEMORY, "a host allocation failed");
    return SPH_ERROR_OUT_OF_HOST_MEMORY;
  } catch (const std::exception& e) {
    report_failure(context, function, SPH_ERROR_INTERNAL, e.what());
    return SPH_ERROR_INTERNAL;
  } catch (...) {
    report_failure(context, function, SPH_ERROR_INTERNAL, "unknown internal exception");
    return SPH_ERROR_INTERNAL;
  }
}

// Holds a world for the duration of one call; a second concurrent call gets WORLD_LOCKED.
class WorldLock {
 public:
  explicit WorldLock(const sph_world* world) : world_(const_cast<sph_world*>(world)) {
    bool expected = false;
    if (!world_->busy.compare_exchange_strong(expected, true))
      throw Error(Status::WorldLocked,
                  "world: it is in use by another call (a world is used from one thread at a time)");
  }
  ~WorldLock() { world_->busy.store(false); }
  WorldLock(const WorldLock&) = delete;
  WorldLock& operator=(const WorldLock&) = delete;

 private:
  sph_world* world_;
};

// Validates a world handle and that its device is alive.
inline void require_world(const sph_world* world) {
  if (!world) throw Error(Status::InvalidHandle, "world: is NULL");
  if (!is_live_handle(world, HandleKind::World))
    throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
  if (world->device_lost)
    throw Error(Status::DeviceLost, "world: its device was lost after a sticky device error; destroy it");
}

inline const sph_context* context_of(const sph_world* world) {
  return (world && is_live_handle(world, HandleKind::World)) ? world->context : nullptr;
}

}  // namespace sph
