// SPDX-License-Identifier: MIT
// What every harness checks after a library call: the result is a known code, a failure comes
// with a message, a success clears it. A violated invariant aborts, which libFuzzer (and the
// replay driver) reports as a crash with the input that caused it.
#ifndef SPH_FUZZ_CHECK_H
#define SPH_FUZZ_CHECK_H

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "sph_c.h"

namespace sph_fuzz {

[[noreturn]] inline void violation(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::fputs("fuzz invariant violated: ", stderr);
  std::vfprintf(stderr, format, args);
  std::fputc('\n', stderr);
  va_end(args);
  std::abort();
}

inline bool is_known_result(sph_result r) {
  const int v = static_cast<int>(r);
  return v == SPH_OK || v == SPH_INCOMPLETE ||
         (v <= SPH_ERROR_INVALID_ARGUMENT && v >= SPH_ERROR_CORRUPT_DATA);
}

// The result contract of every sph_ call (sph_c.h, "Conventions"); returns r.
inline sph_result check_result(sph_result r, const char* call) {
  if (!is_known_result(r)) violation("%s returned %d, not an sph_result value", call, static_cast<int>(r));
  const char* message = sph_get_last_error();
  if (!message) violation("%s: sph_get_last_error() returned NULL", call);
  if (r < 0 && message[0] == '\0')
    violation("%s failed with %d but left no message", call, static_cast<int>(r));
  if (r == SPH_OK && message[0] != '\0')
    violation("%s succeeded but sph_get_last_error() is \"%s\"", call, message);
  return r;
}

// The context every harness works in: the CPU backend on the calling thread alone.
inline sph_context* create_cpu_context() {
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 1;
  sph_context* context = nullptr;
  if (check_result(sph_context_create(&def, &context), "sph_context_create") != SPH_OK)
    violation("no CPU context");
  return context;
}

}  // namespace sph_fuzz

#define FUZZ_CALL(call) ::sph_fuzz::check_result((call), #call)

#endif
