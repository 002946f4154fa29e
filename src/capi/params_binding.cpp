// SPDX-License-Identifier: MIT
#include "params_binding.h"

#include <algorithm>

#include "struct_io.h"

namespace sph {
namespace binding_detail {

void describe_field(const char* name, ParamType type, ZeroMeans zero, const ParamRange& range,
                    uint32_t known_bits, const char* unit, uint32_t offset, const float* defaults,
                    sph_param_field_info& out) {
  std::memset(&out, 0, sizeof out);
  out.struct_size = sizeof out;
  out.offset = offset;
  out.type = static_cast<sph_param_type>(type);
  out.zero = static_cast<sph_param_zero>(zero);
  out.lower_bound = static_cast<sph_param_bound>(range.lower_bound);
  out.upper_bound = static_cast<sph_param_bound>(range.upper_bound);
  out.lower = range.lower;
  out.upper = range.upper;
  if (type == ParamType::Bits) {
    out.lower_bound = SPH_BOUND_NONE;
    out.upper_bound = SPH_BOUND_NONE;
    out.lower = 0.0;
    out.upper = known_bits;
  }
  std::memcpy(out.default_value, defaults, sizeof out.default_value);
  out.name = name;
  out.unit = unit;
}

}  // namespace binding_detail

static_assert(static_cast<uint32_t>(ParamType::Float) == SPH_PARAM_FLOAT &&
                  static_cast<uint32_t>(ParamType::Vector) == SPH_PARAM_VEC3 &&
                  static_cast<uint32_t>(ParamType::Count) == SPH_PARAM_UINT32 &&
                  static_cast<uint32_t>(ParamType::Bits) == SPH_PARAM_FLAGS,
              "ParamType equals sph_param_type");
static_assert(static_cast<uint32_t>(ZeroMeans::Value) == SPH_PARAM_ZERO_IS_VALUE &&
                  static_cast<uint32_t>(ZeroMeans::Default) == SPH_PARAM_ZERO_IS_DEFAULT &&
                  static_cast<uint32_t>(ZeroMeans::Derived) == SPH_PARAM_ZERO_IS_DERIVED,
              "ZeroMeans equals sph_param_zero");
static_assert(static_cast<uint32_t>(Bound::None) == SPH_BOUND_NONE &&
                  static_cast<uint32_t>(Bound::Inclusive) == SPH_BOUND_INCLUSIVE &&
                  static_cast<uint32_t>(Bound::Exclusive) == SPH_BOUND_EXCLUSIVE,
              "Bound equals sph_param_bound");

const ParamsBinding& params_binding(uint32_t kind, const char* what) {
  const std::vector<ParamsBinding>& table = params_bindings();
  if (kind >= table.size())
    throw Error(Status::Unsupported, std::string(what) + ": " + std::to_string(static_cast<int32_t>(kind)) +
                                         " is not an sph_params_kind value");
  return table[kind];
}

PublicParams read_public_params(const ParamsBinding& b, const void* user, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  uint32_t size;
  std::memcpy(&size, user, sizeof size);
  require_plausible_struct_size(size, name, "->struct_size: ");  // before its tail is read
  if (size < b.first_size)
    throw Error(Status::VersionMismatch, std::string(name) + "->struct_size: " + std::to_string(size) +
                                             " is smaller than " + std::to_string(b.first_size) +
                                             "; fill the struct with its _init() function");
  const unsigned char* bytes = static_cast<const unsigned char*>(user);
  for (uint32_t i = b.size; i < size; ++i)
    if (bytes[i] != 0)
      throw Error(Status::Unsupported,
                  std::string(name) + "->struct_size: " + std::to_string(size) +
                      " has fields this library version does not know, and they are not zero");
  PublicParams copy{};  // an older caller's struct: the fields it lacks read as zero (the old behaviour)
  std::memcpy(copy.bytes, bytes, size < b.size ? size : b.size);
  for (const ReservedWord& w : b.reserved) {
    uint32_t v;
    std::memcpy(&v, copy.bytes + w.offset, sizeof v);
    if (v != 0)
      throw Error(Status::InvalidArgument, std::string(name) + "->" + w.name + ": is reserved and must be 0");
  }
  return copy;
}

void apply_public_params(const ParamsBinding& b, const PublicParams& in, const WorldShape& shape,
                         const char* name, RuntimeParams& into) {
  RuntimeParams r = into;
  for (const PartBinding& p : b.parts) p.read(p, in.bytes, r);
  const ParamPath path{"", std::string(name) + "->", Status::InvalidArgument, Status::Unsupported};
  for (const PartBinding& p : b.parts) p.check(r, shape, path);
  into = r;
}

PublicParams public_params(const ParamsBinding& b, const RuntimeParams& r) {
  PublicParams out{};
  for (const PartBinding& p : b.parts) p.write(p, r, out.bytes);
  std::memcpy(out.bytes, &b.size, sizeof b.size);
  return out;
}

std::vector<sph_param_field_info> describe_params(const ParamsBinding& b) {
  std::vector<sph_param_field_info> fields;
  for (const PartBinding& p : b.parts)
    for (uint32_t k = 0; k < p.offsets.size(); ++k) {
      fields.emplace_back();
      p.describe(p, k, fields.back());
    }
  std::stable_sort(
      fields.begin(), fields.end(),
      [](const sph_param_field_info& a, const sph_param_field_info& c) { return a.offset < c.offset; });
  return fields;
}

}  // namespace sph
