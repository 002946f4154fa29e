// SPDX-License-Identifier: MIT
// How a physics method describes itself as data (host only): its runtime parameters with their
// ranges and the meaning of a zero, and its per-particle arrays. Each method's table is the one
// copy of its rules: core/param_validation.h checks a method's Params against it for the C
// layer, checkpoints and scene files, and the C layer describes the public structs to tools
// from it (sph_params_get_field_info).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <type_traits>
#include <utility>

#include "vec3.h"

namespace sph {

// Names a method in templates that visit the method list (methods.h).
template <class Method>
struct Tag {
  using type = Method;
};

// How one end of a range is bounded (values equal to sph_param_bound).
enum class Bound : uint32_t { None = 0, Inclusive = 1, Exclusive = 2 };

// What a zero in the public struct asks for (values equal to sph_param_zero). STYLE.md: a
// struct that is all zeros but for struct_size is valid; a field whose zero was never a valid
// value takes its default, a field where zero is a physical value keeps it.
enum class ZeroMeans : uint32_t {
  Value = 0,    // zero is itself a value (no gravity, an inviscid fluid, no damping)
  Default = 1,  // zero takes the default (the Params member initialiser)
  Derived = 2,  // zero asks for a value derived from the world's shape (kept as 0 in Params)
};

// The kind of a field (values equal to sph_param_type).
enum class ParamType : uint32_t { Float = 0, Vec3 = 1, Count = 2, Bits = 3 };

struct ParamRange {
  double lower;
  Bound lower_bound;
  double upper;
  Bound upper_bound;
};

constexpr ParamRange kAnyFinite{0.0, Bound::None, 0.0, Bound::None};
constexpr ParamRange above(double lower) { return ParamRange{lower, Bound::Exclusive, 0.0, Bound::None}; }
constexpr ParamRange at_least(double lower) { return ParamRange{lower, Bound::Inclusive, 0.0, Bound::None}; }
constexpr ParamRange within(double lower, double upper) {
  return ParamRange{lower, Bound::Inclusive, upper, Bound::Inclusive};
}
constexpr ParamRange above_up_to(double lower, double upper) {
  return ParamRange{lower, Bound::Exclusive, upper, Bound::Inclusive};
}

// One field of a method's Params. Exactly one member pointer is set, by the type. Floats and
// vectors must be finite; Bits may hold only the bits of `known_bits`.
template <class P>
struct ParamField {
  const char* name;  // the public struct's field name, which is also the scene file's key
  ParamType type;
  float P::*real;
  Vec3 P::*vector;
  uint32_t P::*integer;
  ParamRange range;  // Float and Count
  uint32_t known_bits;
  ZeroMeans zero;
  const char* unit;  // SI, "" when dimensionless
};

template <class P>
constexpr ParamField<P> real_field(const char* name, float P::*member, ParamRange range, ZeroMeans zero,
                                   const char* unit) {
  return ParamField<P>{name, ParamType::Float, member, nullptr, nullptr, range, 0u, zero, unit};
}
template <class P>
constexpr ParamField<P> vector_field(const char* name, Vec3 P::*member, ZeroMeans zero, const char* unit) {
  return ParamField<P>{name, ParamType::Vec3, nullptr, member, nullptr, kAnyFinite, 0u, zero, unit};
}
template <class P>
constexpr ParamField<P> count_field(const char* name, uint32_t P::*member, ParamRange range, ZeroMeans zero) {
  return ParamField<P>{name, ParamType::Count, nullptr, nullptr, member, range, 0u, zero, ""};
}
template <class P>
constexpr ParamField<P> bits_field(const char* name, uint32_t P::*member, uint32_t known_bits) {
  return ParamField<P>{name,       ParamType::Bits, nullptr,          nullptr, member,
                       kAnyFinite, known_bits,      ZeroMeans::Value, ""};
}

// Calls visit(std::integral_constant<size_t, k>{}) for each field k of Method::kFields, so that
// the visitor can read the field as a constant (Method::kFields[k]) and branch on its type at
// compile time.
template <class Method, class Visit, size_t... K>
void visit_fields(Visit&& visit, std::index_sequence<K...>) {
  (visit(std::integral_constant<size_t, K>{}), ...);
}
template <class Method, class Visit>
void for_each_field(Visit&& visit) {
  visit_fields<Method>(visit,
                       std::make_index_sequence<sizeof(Method::kFields) / sizeof(Method::kFields[0])>{});
}
template <class Method>
constexpr size_t field_count() {
  return sizeof(Method::kFields) / sizeof(Method::kFields[0]);
}

// A cross-field rule that a method's check() found broken, as parts of the message
// "<field>: <value> <relation> [<other_field>] <other_value>" that validate() prefixes with the
// caller's path ("params->dt_max: 1e-07 is smaller than params->dt_min 1e-06").
struct ParamConflict {
  const char* field = nullptr;
  float value = 0.0f;
  const char* relation = "";
  const char* other_field = nullptr;  // a field of the same struct, or null for a world value
  float other_value = 0.0f;
};

}  // namespace sph
