// Argument checks shared by the C entry points; each throws Error with the argument's name.
#pragma once

#include <stdint.h>

#include <cmath>
#include <cstring>
#include <string>

#include "../core/status.h"
#include "sph_c.h"

namespace sph {

inline std::string describe(float v) { return std::to_string(v); }

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

inline void require_zero(uint32_t v, const char* name) {
  if (v != 0) throw Error(Status::InvalidArgument, std::string(name) + ": is reserved and must be 0");
}

}  // namespace sph
