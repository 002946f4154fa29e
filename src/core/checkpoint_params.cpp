// SPDX-License-Identifier: MIT
#include "checkpoint_params.h"

#include <string>

#include "param_validation.h"

namespace sph {
namespace {

[[noreturn]] void corrupt_params(const ByteReader& r, const std::string& message) {
  throw Error(Status::CorruptData, "checkpoint: " + r.what() + ": " + message);
}

template <class Method>
void write_block(ByteWriter& w, const typename Method::Params& p) {
  const std::string name = Method::kName;
  w.u32(static_cast<uint32_t>(name.size()));
  w.bytes(name.data(), name.size());
  w.u32(static_cast<uint32_t>(field_count<Method>()));
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    if constexpr (f.type == ParamType::Float) w.f32(p.*f.real);
    if constexpr (f.type == ParamType::Vector) {
      w.f32((p.*f.vector).x);
      w.f32((p.*f.vector).y);
      w.f32((p.*f.vector).z);
    }
    if constexpr (f.type == ParamType::Count || f.type == ParamType::Bits) w.u32(p.*f.integer);
  });
}

// The first `count` fields of a block; the rest keep their defaults (a block written before
// the method grew a field).
template <class Method>
void read_fields(ByteReader& r, uint32_t count, typename Method::Params& p) {
  for_each_field<Method>([&](auto k) {
    constexpr ParamField<typename Method::Params> f = Method::kFields[decltype(k)::value];
    if (decltype(k)::value >= count) return;
    if constexpr (f.type == ParamType::Float) p.*f.real = r.f32();
    if constexpr (f.type == ParamType::Vector) {
      (p.*f.vector).x = r.f32();
      (p.*f.vector).y = r.f32();
      (p.*f.vector).z = r.f32();
    }
    if constexpr (f.type == ParamType::Count || f.type == ParamType::Bits) p.*f.integer = r.u32();
  });
}

// Every method's Params against its table, named "<method>.<field>" in messages.
void validate_all(const ByteReader& r, const RuntimeParams& p, const WorldConfig& config) {
  for_each_params(p, [&](auto tag, const auto& params) {
    using Method = typename decltype(tag)::type;
    const ParamPath path{"checkpoint: " + r.what() + ": ", std::string(Method::kName) + ".",
                         Status::CorruptData, Status::CorruptData};
    validate<Method>(params, config.shape(), path);
  });
}

constexpr uint32_t kMaxNameLength = 64;
constexpr uint32_t kMaxBlocks = 64;

}  // namespace

void write_params(ByteWriter& w, const RuntimeParams& p) {
  uint32_t blocks = 0;
  for_each_params(p, [&](auto, const auto&) { ++blocks; });
  w.u32(blocks);
  for_each_params(
      p, [&](auto tag, const auto& params) { write_block<typename decltype(tag)::type>(w, params); });
}

RuntimeParams read_params(ByteReader& r, const WorldConfig& config) {
  RuntimeParams p;
  const uint32_t blocks = r.u32();
  if (blocks > kMaxBlocks)
    corrupt_params(r, std::to_string(blocks) + " parameter blocks, more than " + std::to_string(kMaxBlocks));
  std::string seen = "|";
  for (uint32_t b = 0; b < blocks; ++b) {
    const uint32_t length = r.u32();
    if (length == 0 || length > kMaxNameLength)
      corrupt_params(
          r, "parameter block " + std::to_string(b) + " has a name of " + std::to_string(length) + " bytes");
    r.need(length);
    std::string name(length, '\0');
    for (char& c : name) c = static_cast<char>(r.u8());
    if (seen.find("|" + name + "|") != std::string::npos)
      corrupt_params(r, "the parameters of '" + name + "' appear twice");
    seen += name + "|";
    const uint32_t count = r.u32();
    bool known = false;
    for_each_params(p, [&](auto tag, auto& params) {
      using Method = typename decltype(tag)::type;
      if (known || name != Method::kName) return;
      known = true;
      if (count > field_count<Method>())
        corrupt_params(r, "'" + name + "' has " + std::to_string(count) + " fields; this library knows " +
                              std::to_string(field_count<Method>()));
      read_fields<Method>(r, count, params);
    });
    if (!known) corrupt_params(r, "parameters of an unknown method '" + name + "'");
  }
  validate_all(r, p, config);
  return p;
}

RuntimeParams read_params_v1(ByteReader& r, const WorldConfig& config) {
  RuntimeParams p;
  Stepping::Params& s = p.stepping;
  MethodParams& m = p.methods;
  s.gravity.x = r.f32();
  s.gravity.y = r.f32();
  s.gravity.z = r.f32();
  m.ideal_gas.stiffness = r.f32();
  m.mueller.viscosity = r.f32();
  s.step_factor = r.f32();
  s.dt_min = r.f32();
  s.dt_max = r.f32();
  s.max_substeps = r.u32();
  s.step_limits = r.u32();
  m.surface_tension.coefficient = r.f32();
  m.surface_tension.normal_threshold = r.f32();
  m.clavet.linear = r.f32();
  m.clavet.quadratic = r.f32();
  m.tait.speed_of_sound = r.f32();
  // Version 1 wrote the spring parameters only for a world with springs.
  if (config.features & kFeatureSprings) {
    m.springs.stiffness = r.f32();
    m.springs.link_radius = r.f32();
    m.springs.yield_ratio = r.f32();
    m.springs.plasticity = r.f32();
    m.springs.damping = r.f32();
  }
  validate_all(r, p, config);
  return p;
}

}  // namespace sph
