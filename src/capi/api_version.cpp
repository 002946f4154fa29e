// SPDX-License-Identifier: MIT
// Version queries, result strings and the last-error accessor: always thread-safe.
#include "guard.h"
#include "handles.h"
#include "last_error.h"
#include "sph_c.h"

#ifndef SPH_GIT_REVISION
#define SPH_GIT_REVISION "unknown"
#endif
#ifndef SPH_CUDA_ARCHITECTURES
#define SPH_CUDA_ARCHITECTURES "none"
#endif

#define SPH_STRINGIFY2(x) #x
#define SPH_STRINGIFY(x) SPH_STRINGIFY2(x)

static_assert(static_cast<int>(sph::Status::NonFinite) == SPH_ERROR_NON_FINITE, "status codes match");
static_assert(static_cast<int>(sph::Status::CorruptData) == SPH_ERROR_CORRUPT_DATA, "status codes match");
static_assert(static_cast<int>(sph::Status::Capacity) == SPH_ERROR_CAPACITY, "status codes match");
static_assert(static_cast<int>(sph::Status::Incomplete) == SPH_INCOMPLETE, "status codes match");

extern "C" {

SPH_API uint32_t SPH_CALL sph_get_version(void) { return SPH_VERSION; }

SPH_API uint32_t SPH_CALL sph_get_abi_version(void) { return SPH_ABI_VERSION; }

SPH_API const char* SPH_CALL sph_get_build_info(void) {
  return "sph " SPH_STRINGIFY(SPH_VERSION_MAJOR) "." SPH_STRINGIFY(SPH_VERSION_MINOR) "." SPH_STRINGIFY(
      SPH_VERSION_PATCH) " (git " SPH_GIT_REVISION "); compiler " __VERSION__
                         "; backends: cpu"
#if defined(SPH_HAVE_CUDA)
                         " cuda (architectures " SPH_CUDA_ARCHITECTURES
                         ")"
#endif
#if defined(SPH_SANITIZE_BUILD)
                         "; sanitizers: address,undefined"
#endif
      ;
}

SPH_API const char* SPH_CALL sph_result_string(sph_result result) {
  switch (result) {
    case SPH_INCOMPLETE:
      return "SPH_INCOMPLETE: the call did only part of the work";
    case SPH_OK:
      return "SPH_OK: success";
    case SPH_ERROR_INVALID_ARGUMENT:
      return "SPH_ERROR_INVALID_ARGUMENT: an argument is NULL, non-finite or out of range";
    case SPH_ERROR_INVALID_HANDLE:
      return "SPH_ERROR_INVALID_HANDLE: a NULL, destroyed or foreign object";
    case SPH_ERROR_VERSION_MISMATCH:
      return "SPH_ERROR_VERSION_MISMATCH: struct_size or header version not accepted";
    case SPH_ERROR_UNSUPPORTED:
      return "SPH_ERROR_UNSUPPORTED: not built in, no such device, or an unknown enum value";
    case SPH_ERROR_FEATURE_DISABLED:
      return "SPH_ERROR_FEATURE_DISABLED: the feature is off in the world's def";
    case SPH_ERROR_CAPACITY:
      return "SPH_ERROR_CAPACITY: a size limit was exceeded (particles beyond max_capacity, too many in one "
             "cell, a "
             "grid too large)";
    case SPH_ERROR_OUT_OF_HOST_MEMORY:
      return "SPH_ERROR_OUT_OF_HOST_MEMORY: a host allocation failed";
    case SPH_ERROR_OUT_OF_DEVICE_MEMORY:
      return "SPH_ERROR_OUT_OF_DEVICE_MEMORY: a device allocation failed";
    case SPH_ERROR_WORLD_LOCKED:
      return "SPH_ERROR_WORLD_LOCKED: the world is in use by another call";
    case SPH_ERROR_BUSY:
      return "SPH_ERROR_BUSY: the object is still in use";
    case SPH_ERROR_DEVICE:
      return "SPH_ERROR_DEVICE: a device or driver error";
    case SPH_ERROR_DEVICE_LOST:
      return "SPH_ERROR_DEVICE_LOST: the device was lost; destroy the world";
    case SPH_ERROR_INTERNAL:
      return "SPH_ERROR_INTERNAL: an internal invariant failed";
    case SPH_ERROR_BUFFER_TOO_SMALL:
      return "SPH_ERROR_BUFFER_TOO_SMALL: a caller buffer is too small";
    case SPH_ERROR_NON_FINITE:
      return "SPH_ERROR_NON_FINITE: a step produced NaN or Inf; the world was rolled back";
    case SPH_ERROR_CORRUPT_DATA:
      return "SPH_ERROR_CORRUPT_DATA: input data is truncated, damaged or inconsistent";
    default:
      return "unknown sph_result";
  }
}

SPH_API const char* SPH_CALL sph_get_last_error(void) { return sph::last_error(); }

SPH_API sph_result SPH_CALL sph_get_live_object_count(uint32_t* out_count) {
  return sph::guarded("sph_get_live_object_count", nullptr, [&] {
    if (!out_count) return sph::fail(sph::Status::InvalidArgument, "out_count: is NULL");
    *out_count = sph::live_handle_count();
    return SPH_OK;
  });
}

}  // extern "C"
