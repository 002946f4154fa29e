// SPDX-License-Identifier: MIT
#include "param_validation.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "number_text.h"

namespace sph {
namespace {

[[noreturn]] void fail(Status status, const ParamPath& path, const char* name, const std::string& what) {
  throw Error(status, path.where + path.scope + name + ": " + what);
}

bool below_lower(double v, const ParamRange& r) {
  return (r.lower_bound == Bound::Inclusive && !(v >= r.lower)) ||
         (r.lower_bound == Bound::Exclusive && !(v > r.lower));
}

bool above_upper(double v, const ParamRange& r) {
  return (r.upper_bound == Bound::Inclusive && !(v <= r.upper)) ||
         (r.upper_bound == Bound::Exclusive && !(v < r.upper));
}

}  // namespace

std::string describe_range(const ParamRange& r) {
  const bool low = r.lower_bound != Bound::None, high = r.upper_bound != Bound::None;
  if (low && high)
    return std::string("in ") + (r.lower_bound == Bound::Inclusive ? "[" : "(") + number_text(r.lower) +
           ", " + number_text(r.upper) + (r.upper_bound == Bound::Inclusive ? "]" : ")");
  if (low) return (r.lower_bound == Bound::Inclusive ? ">= " : "> ") + number_text(r.lower);
  if (high) return (r.upper_bound == Bound::Inclusive ? "<= " : "< ") + number_text(r.upper);
  return "finite";
}

std::string describe_value(float value) {
  char buf[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, static_cast<double>(value));
    if (std::strtof(buf, nullptr) == value) break;
  }
  return buf;
}

void check_real(float value, const char* name, const ParamRange& range, const ParamPath& path) {
  if (!std::isfinite(value)) fail(path.invalid, path, name, "is not finite");
  if (below_lower(value, range) || above_upper(value, range))
    fail(path.invalid, path, name, "must be " + describe_range(range) + ", got " + describe_value(value));
}

void check_vector(Vec3 value, const char* name, const ParamPath& path) {
  if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z))
    fail(path.invalid, path, name, "has a non-finite component");
}

void check_count(uint32_t value, const char* name, const ParamRange& range, const ParamPath& path) {
  if (below_lower(value, range) || above_upper(value, range))
    fail(path.invalid, path, name, "must be " + describe_range(range) + ", got " + std::to_string(value));
}

void check_bits(uint32_t value, const char* name, uint32_t known_bits, const ParamPath& path) {
  if (value & ~known_bits) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%x", value & ~known_bits);
    fail(path.unknown, path, name, std::string("unknown bits ") + buf);
  }
}

void throw_conflict(const ParamConflict& c, const ParamPath& path) {
  std::string what = describe_value(c.value) + " " + c.relation + " ";
  if (c.other_field) what += path.scope + c.other_field + " ";
  what += describe_value(c.other_value);
  fail(path.invalid, path, c.field, what);
}

}  // namespace sph
