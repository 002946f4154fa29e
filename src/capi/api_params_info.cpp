// SPDX-License-Identifier: MIT
// Parameters and methods described as data, for tools: read from the same tables the set calls
// validate against (params_binding.h, physics/methods.h), so a tool sees the library's rules.
#include "guard.h"
#include "init_struct.h"
#include "params_binding.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

struct MethodEntry {
  const char* name;
  sph::MethodSwitch selector;
};

std::vector<MethodEntry> methods() {
  std::vector<MethodEntry> out;
  sph::for_each_method([&](auto tag) {
    using Method = typename decltype(tag)::type;
    out.push_back(MethodEntry{Method::kName, switch_of(tag)});
  });
  return out;
}

// The params struct that holds a method's fields, if any.
const sph::ParamsBinding* binding_of(const char* method) {
  for (const sph::ParamsBinding& b : sph::params_bindings())
    for (const sph::PartBinding& p : b.parts)
      if (std::string(p.method) == method) return &b;
  return nullptr;
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_params_info_init_sized(sph_params_info* info, uint32_t size) {
  return sph::init_user_struct("sph_params_info_init", "info", info, size);
}

SPH_API sph_result SPH_CALL sph_params_get_info(sph_params_kind kind, sph_params_info* out) {
  return sph::guarded("sph_params_get_info", nullptr, [&] {
    const sph::ParamsBinding& b = sph::params_binding(sph::enum_bits(kind), "kind");
    sph_params_info info = sph::zeroed_struct<sph_params_info>();
    info.params_size = b.size;
    info.field_count = static_cast<uint32_t>(sph::describe_params(b).size());
    info.name = b.name;
    info.type_name = b.type_name;
    sph::write_output_struct(out, info, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_param_field_info_init_sized(sph_param_field_info* info, uint32_t size) {
  return sph::init_user_struct("sph_param_field_info_init", "info", info, size);
}

SPH_API sph_result SPH_CALL sph_params_get_field_info(sph_params_kind kind, uint32_t index,
                                                      sph_param_field_info* out) {
  return sph::guarded("sph_params_get_field_info", nullptr, [&] {
    const sph::ParamsBinding& b = sph::params_binding(sph::enum_bits(kind), "kind");
    const std::vector<sph_param_field_info> fields = sph::describe_params(b);
    if (index >= fields.size())
      throw Error(Status::InvalidArgument, "index: " + std::to_string(index) + " is past the last field of " +
                                               b.type_name + " (" + std::to_string(fields.size()) +
                                               " fields)");
    sph::write_output_struct(out, fields[index], "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_physics_method_info_init_sized(sph_physics_method_info* info, uint32_t size) {
  return sph::init_user_struct("sph_physics_method_info_init", "info", info, size);
}

SPH_API sph_result SPH_CALL sph_get_physics_method_info(uint32_t index, sph_physics_method_info* out) {
  return sph::guarded("sph_get_physics_method_info", nullptr, [&] {
    const std::vector<MethodEntry> all = methods();
    if (index >= all.size())
      throw Error(Status::InvalidArgument, "index: " + std::to_string(index) + " is past the last method (" +
                                               std::to_string(all.size()) + " methods)");
    sph_physics_method_info info = sph::zeroed_struct<sph_physics_method_info>();
    info.method_count = static_cast<uint32_t>(all.size());
    info.switch_by = static_cast<sph_method_switch>(all[index].selector.kind);
    info.value = all[index].selector.value;
    const sph::ParamsBinding* b = binding_of(all[index].name);
    info.has_params = b ? 1u : 0u;
    info.params_kind = b ? b->kind : SPH_PARAMS_WORLD;
    info.name = all[index].name;
    sph::write_output_struct(out, info, "out");
    return SPH_OK;
  });
}

}  // extern "C"

static_assert(static_cast<uint32_t>(sph::SwitchKind::Feature) == SPH_METHOD_SWITCH_FEATURE &&
                  static_cast<uint32_t>(sph::SwitchKind::Viscosity) == SPH_METHOD_SWITCH_VISCOSITY &&
                  static_cast<uint32_t>(sph::SwitchKind::Solver) == SPH_METHOD_SWITCH_SOLVER &&
                  static_cast<uint32_t>(sph::SwitchKind::EquationOfState) ==
                      SPH_METHOD_SWITCH_EQUATION_OF_STATE,
              "SwitchKind equals sph_method_switch");
