// SPDX-License-Identifier: MIT
// Public params structs bound to the methods' Params they carry, so that one code path reads,
// validates (core/param_validation.h), installs, writes back and describes every params struct:
// a binding names, for each method whose fields the struct holds, the byte offset of each field
// of the method's table (physics/param_table.h), plus the struct's reserved words. The table of
// bindings is api_physics_options.cpp's; adding a method adds one line there.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <cstring>
#include <string>
#include <vector>

#include "../core/config.h"
#include "../core/param_validation.h"
#include "sph_c.h"
#include "struct_io.h"

namespace sph {

struct ReservedWord {
  const char* name;  // "reserved0"
  uint32_t offset;
};

// One method's fields inside a public struct, with its Params' operations type-erased.
struct PartBinding {
  const char* method;             // Method::kName
  std::vector<uint32_t> offsets;  // of each field of Method::kFields, in table order
  void (*read)(const PartBinding&, const unsigned char* in, RuntimeParams& into);  // with the zero rule
  void (*check)(const RuntimeParams&, const WorldShape&, const ParamPath&);
  void (*write)(const PartBinding&, const RuntimeParams&, unsigned char* out);
  void (*describe)(const PartBinding&, uint32_t field, sph_param_field_info& out);
};

struct ParamsBinding {
  sph_params_kind kind;
  const char* name;       // "tait": the scene file's key
  const char* type_name;  // "sph_tait_params"
  uint32_t size;          // sizeof the public struct
  uint32_t first_size;    // its size in the first release that had it (struct_io.h, kFirstStructSize)
  // The method whose switch must be on for the struct to be used (FEATURE_DISABLED otherwise,
  // naming `requirement`); null for the world's own parameters.
  bool (*enabled)(const MethodSelection&);
  const char* requirement;
  std::vector<PartBinding> parts;
  std::vector<ReservedWord> reserved;
};

namespace binding_detail {

template <class Method>
void read(const PartBinding& b, const unsigned char* in, RuntimeParams& into) {
  typename Method::Params& p = params_of<Method>(into);
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    const unsigned char* at = in + b.offsets[decltype(k)::value];
    if constexpr (f.type == ParamType::Float) std::memcpy(&(p.*f.real), at, sizeof(float));
    if constexpr (f.type == ParamType::Vector) std::memcpy(&(p.*f.vector), at, sizeof(Vec3));
    if constexpr (f.type == ParamType::Count || f.type == ParamType::Bits)
      std::memcpy(&(p.*f.integer), at, sizeof(uint32_t));
  });
  apply_zero_defaults<Method>(p);
}

template <class Method>
void check(const RuntimeParams& r, const WorldShape& shape, const ParamPath& path) {
  validate<Method>(params_of<Method>(r), shape, path);
}

template <class Method>
void write(const PartBinding& b, const RuntimeParams& r, unsigned char* out) {
  const typename Method::Params& p = params_of<Method>(r);
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    unsigned char* at = out + b.offsets[decltype(k)::value];
    if constexpr (f.type == ParamType::Float) std::memcpy(at, &(p.*f.real), sizeof(float));
    if constexpr (f.type == ParamType::Vector) std::memcpy(at, &(p.*f.vector), sizeof(Vec3));
    if constexpr (f.type == ParamType::Count || f.type == ParamType::Bits)
      std::memcpy(at, &(p.*f.integer), sizeof(uint32_t));
  });
}

void describe_field(const char* name, ParamType type, ZeroMeans zero, const ParamRange& range,
                    uint32_t known_bits, const char* unit, uint32_t offset, const float* defaults,
                    sph_param_field_info& out);

template <class Method>
void describe(const PartBinding& b, uint32_t field, sph_param_field_info& out) {
  const typename Method::Params defaults{};
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    if (decltype(k)::value != field) return;
    float values[3] = {0.0f, 0.0f, 0.0f};
    if constexpr (f.type == ParamType::Float) values[0] = defaults.*f.real;
    if constexpr (f.type == ParamType::Vector) {
      const Vec3 v = defaults.*f.vector;
      values[0] = v.x, values[1] = v.y, values[2] = v.z;
    }
    if constexpr (f.type == ParamType::Count || f.type == ParamType::Bits)
      values[0] = static_cast<float>(defaults.*f.integer);
    describe_field(f.name, f.type, f.zero, f.range, f.known_bits, f.unit, b.offsets[field], values, out);
  });
}

}  // namespace binding_detail

// The fields of Method inside a public struct: offsets[k] is where Method::kFields[k] lives.
template <class Method, size_t N>
PartBinding part(const uint32_t (&offsets)[N]) {
  static_assert(N == field_count<Method>(), "one offset per field of the method");
  return PartBinding{Method::kName,
                     std::vector<uint32_t>(offsets, offsets + N),
                     &binding_detail::read<Method>,
                     &binding_detail::check<Method>,
                     &binding_detail::write<Method>,
                     &binding_detail::describe<Method>};
}

template <class Method>
bool method_runs(const MethodSelection& s) {
  return runs(s, Tag<Method>{});
}

// A method's own params struct, set only on a world that runs the method.
template <class Method, class Public, size_t N>
ParamsBinding option(sph_params_kind kind, const char* type_name, const char* requirement,
                     const uint32_t (&offsets)[N], std::vector<ReservedWord> reserved) {
  return ParamsBinding{kind,
                       Method::kName,
                       type_name,
                       sizeof(Public),
                       kFirstStructSize<Public>,
                       &method_runs<Method>,
                       requirement,
                       {part<Method>(offsets)},
                       std::move(reserved)};
}

// The table (api_physics_options.cpp), indexed by sph_params_kind.
const std::vector<ParamsBinding>& params_bindings();
// The binding of a kind; Error(Unsupported) naming `what` for an unknown kind.
const ParamsBinding& params_binding(uint32_t kind, const char* what);

// A public params struct as bytes, without allocating (the set and get calls must not fail for
// memory): every struct of the table fits (checked where the table is built).
constexpr size_t kMaxPublicParamsSize = 128;
struct PublicParams {
  unsigned char bytes[kMaxPublicParamsSize];
};

// The caller's struct (struct_size rules of struct_io.h) as bytes of the library's size, its
// reserved words checked: a struct from an older header (first_size up to size) reads the fields
// it lacks as zero.
PublicParams read_public_params(const ParamsBinding& b, const void* user, const char* name);
// Public bytes into the runtime parameters: fields copied with the zero rule, then validated
// (InvalidArgument / Unsupported with "name->field" messages). Changes only `into`.
void apply_public_params(const ParamsBinding& b, const PublicParams& in, const WorldShape& shape,
                         const char* name, RuntimeParams& into);
// The public struct of the runtime parameters (reserved words 0, struct_size set).
PublicParams public_params(const ParamsBinding& b, const RuntimeParams& r);
// The described fields in the order of the struct.
std::vector<sph_param_field_info> describe_params(const ParamsBinding& b);

}  // namespace sph
