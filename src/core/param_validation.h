// SPDX-License-Identifier: MIT
// The one check of a method's runtime parameters against its table (physics/param_table.h)
// and its cross-field rule, for every path that sets them: the C layer (set calls, and through
// it scene files) and the checkpoint reader. A failure throws Error with the caller's status
// and a message that names the field by the caller's path:
//   C layer:    InvalidArgument  "params->speed_of_sound: must be > 0, got -1"
//   checkpoint: CorruptData      "checkpoint: section 'parameters': tait.speed_of_sound: ..."
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <string>

#include "../physics/param_table.h"
#include "../physics/world_shape.h"
#include "status.h"

namespace sph {

// Where a check is asked from: a message reads where + scope + field + ": " + what, and a
// cross-field rule names the other field as scope + field.
struct ParamPath {
  std::string where;                         // "" or "checkpoint: section 'parameters': "
  std::string scope;                         // "params->" or "tait."
  Status invalid = Status::InvalidArgument;  // a value out of range or not finite
  Status unknown = Status::Unsupported;      // bits this library does not know
};

// What a field's bounds and zero rule say, for messages ("> 0", "in [0, 1]") and docs.
std::string describe_range(const ParamRange& range);
// The shortest decimal that reads back as the same float ("0.036", "-1", "1e-07").
std::string describe_value(float value);

void check_real(float value, const char* name, const ParamRange& range, const ParamPath& path);
void check_vector(Vec3 value, const char* name, const ParamPath& path);
void check_count(uint32_t value, const char* name, const ParamRange& range, const ParamPath& path);
void check_bits(uint32_t value, const char* name, uint32_t known_bits, const ParamPath& path);
[[noreturn]] void throw_conflict(const ParamConflict& conflict, const ParamPath& path);

// Every field of a method's Params in table order, then its cross-field rule.
template <class Method>
void validate(const typename Method::Params& p, const WorldShape& shape, const ParamPath& path) {
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    if constexpr (f.type == ParamType::Float) check_real(p.*f.real, f.name, f.range, path);
    if constexpr (f.type == ParamType::Vec3) check_vector(p.*f.vector, f.name, path);
    if constexpr (f.type == ParamType::Count) check_count(p.*f.integer, f.name, f.range, path);
    if constexpr (f.type == ParamType::Bits) check_bits(p.*f.integer, f.name, f.known_bits, path);
  });
  ParamConflict conflict;
  if (!Method::check(p, shape, conflict)) throw_conflict(conflict, path);
}

// The zero rule of the public structs: every field whose table says ZeroMeans::Default and
// that holds 0 takes its default (the Params member initialiser).
template <class Method>
void apply_zero_defaults(typename Method::Params& p) {
  const typename Method::Params defaults{};
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    if constexpr (f.zero == ZeroMeans::Default && f.type == ParamType::Float) {
      if (p.*f.real == 0.0f) p.*f.real = defaults.*f.real;
    }
    if constexpr (f.zero == ZeroMeans::Default && (f.type == ParamType::Count || f.type == ParamType::Bits)) {
      if (p.*f.integer == 0u) p.*f.integer = defaults.*f.integer;
    }
  });
}

}  // namespace sph
