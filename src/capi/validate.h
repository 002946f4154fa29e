// SPDX-License-Identifier: MIT
// Argument checks shared by the C entry points; each throws Error with the argument's name.
#pragma once

#include <stdint.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "../core/status.h"
#include "sph_c.h"

namespace sph {

// A float as a message shows it: the fewest significant digits (6 to 9) that read back as the
// same float, so "-1e-07" rather than std::to_string's "-0.000000", and 0.099999994 apart from 0.1.
inline std::string describe(float v) {
  char text[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(v));
    if (std::strtof(text, nullptr) == v || std::isnan(v)) break;
  }
  return text;
}

// The raw 32-bit value of an enum field or argument from the caller. C code and FFIs can put
// any value in an sph_* enum (-1, say), but in C++ loading a value outside the enum's range is
// undefined behaviour (UBSan: "not a valid value for type"), so caller enums are read as
// integers and validated before they are used as enums.
template <class E>
inline uint32_t enum_bits(const E& value) {
  static_assert(sizeof(E) == sizeof(uint32_t), "sph_* enums are 32 bits");
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

inline void require_finite(float v, const char* name) {
  if (!std::isfinite(v)) throw Error(Status::InvalidArgument, std::string(name) + ": is not finite");
}

inline void require_positive(float v, const char* name) {
  require_finite(v, name);
  if (!(v > 0.0f))
    throw Error(Status::InvalidArgument, std::string(name) + ": must be > 0, got " + describe(v));
}

inline void require_non_negative(float v, const char* name) {
  require_finite(v, name);
  if (v < 0.0f)
    throw Error(Status::InvalidArgument, std::string(name) + ": must be >= 0, got " + describe(v));
}

inline void require_finite_vec3(const sph_vec3& v, const char* name) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw Error(Status::InvalidArgument, std::string(name) + ": has a non-finite component");
}

// The bytes an array of `count` elements of `element` bytes, `stride` bytes apart, covers from
// its first byte to its last: (count - 1) * stride + element (0 for no element). A span that
// does not fit in 64 bits, or that runs past the end of the address space from `base`, is no
// real array: InvalidArgument naming `name` (a saturated size would pass a size check against
// a caller's UINT64_MAX and let the copy wrap around memory).
inline uint64_t require_array_span(const void* base, uint64_t count, uint64_t stride, uint64_t element,
                                   const std::string& name) {
  if (count == 0) return 0;
  const uint64_t gaps = count - 1;
  if (gaps != 0 && stride > (UINT64_MAX - element) / gaps)
    throw Error(Status::InvalidArgument, name + ": " + std::to_string(count) + " elements at stride " +
                                             std::to_string(stride) + " span more than 2^64 bytes");
  const uint64_t span = gaps * stride + element;
  if (span > static_cast<uint64_t>(PTRDIFF_MAX))
    throw Error(Status::InvalidArgument, name + ": " + std::to_string(count) + " elements at stride " +
                                             std::to_string(stride) + " span " + std::to_string(span) +
                                             " bytes, more than any object can have (PTRDIFF_MAX)");
  if (reinterpret_cast<uintptr_t>(base) > UINTPTR_MAX - (span - 1))
    throw Error(Status::InvalidArgument, name + ": " + std::to_string(span) +
                                             " bytes from its address run past the end of the address space");
  return span;
}

inline void require_zero(uint32_t v, const char* name) {
  if (v != 0) throw Error(Status::InvalidArgument, std::string(name) + ": is reserved and must be 0");
}

}  // namespace sph
