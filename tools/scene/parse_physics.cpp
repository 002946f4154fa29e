// SPDX-License-Identifier: MIT
// The physics methods and their parameters, read through the library's description of them
// (sph_get_physics_method_info, sph_params_get_info, sph_params_get_field_info): a method the
// library adds needs no code here. Values are checked for their JSON type only; their ranges
// are the library's to check when the world is built (SceneRuntime reports its message at the
// field's path), so the file and the C API accept exactly the same values.
#include <cstring>
#include <limits>

#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {
namespace {

std::vector<sph_physics_method_info> library_methods() {
  std::vector<sph_physics_method_info> out;
  for (uint32_t i = 0;; ++i) {
    sph_physics_method_info m;
    sph_physics_method_info_init(&m);
    if (sph_get_physics_method_info(i, &m) != SPH_OK) break;
    out.push_back(m);
    if (i + 1 >= m.method_count) break;
  }
  return out;
}

std::vector<sph_physics_method_info> methods_switched_by(sph_method_switch field) {
  std::vector<sph_physics_method_info> out;
  for (const sph_physics_method_info& m : library_methods())
    if (m.switch_by == field) out.push_back(m);
  return out;
}

std::vector<std::string> names_of(const std::vector<sph_physics_method_info>& methods) {
  std::vector<std::string> names;
  for (const sph_physics_method_info& m : methods) names.push_back(m.name);
  return names;
}

bool world_runs(const sph_world_def& world, const sph_physics_method_info& m) {
  switch (m.switch_by) {
    case SPH_METHOD_SWITCH_FEATURE:
      return (world.features & m.value) != 0;
    case SPH_METHOD_SWITCH_VISCOSITY:
      return static_cast<uint32_t>(world.viscosity_method) == m.value;
    case SPH_METHOD_SWITCH_EQUATION_OF_STATE:
      return static_cast<uint32_t>(world.equation_of_state) == m.value;
    case SPH_METHOD_SWITCH_SOLVER:
      return static_cast<uint32_t>(world.solver) == m.value;
    default:
      return true;
  }
}

std::string how_to_turn_on(const sph_physics_method_info& m) {
  const std::string name = std::string("\"") + m.name + "\"";
  switch (m.switch_by) {
    case SPH_METHOD_SWITCH_FEATURE:
      return "add " + name + " to world.features";
    case SPH_METHOD_SWITCH_VISCOSITY:
      return "set world.viscosity_method to " + name;
    case SPH_METHOD_SWITCH_EQUATION_OF_STATE:
      return "set world.equation_of_state to " + name;
    case SPH_METHOD_SWITCH_SOLVER:
      return "set world.solver to " + name;
    default:
      return "";
  }
}

std::vector<sph_param_field_info> fields_of(sph_params_kind kind) {
  sph_params_info info;
  sph_params_info_init(&info);
  std::vector<sph_param_field_info> fields;
  if (sph_params_get_info(kind, &info) != SPH_OK) return fields;
  for (uint32_t k = 0; k < info.field_count; ++k) {
    sph_param_field_info f;
    sph_param_field_info_init(&f);
    if (sph_params_get_field_info(kind, k, &f) == SPH_OK) fields.push_back(f);
  }
  return fields;
}

}  // namespace

void parse_params_fields(const JsonNode& node, sph_params_kind kind, const char* what, unsigned char* bytes) {
  const std::vector<sph_param_field_info> fields = fields_of(kind);
  std::vector<std::string> names;
  for (const sph_param_field_info& f : fields) names.push_back(f.name);
  node.expect_object(what, names);
  for (const sph_param_field_info& f : fields) {
    const JsonNode value = node[f.name];
    if (value.missing()) continue;
    unsigned char* at = bytes + f.offset;
    if (f.type == SPH_PARAM_FLOAT) {
      const float v = static_cast<float>(value.number());
      std::memcpy(at, &v, sizeof v);
    } else if (f.type == SPH_PARAM_VEC3) {
      const sph_vec3 v = value.vec3();
      std::memcpy(at, &v, sizeof v);
    } else {
      const uint32_t v = value.count(0, std::numeric_limits<uint32_t>::max());
      std::memcpy(at, &v, sizeof v);
    }
  }
}

std::vector<PhysicsDesc> parse_physics(const JsonNode& node, const sph_world_def& world) {
  std::vector<PhysicsDesc> out;
  if (node.missing()) return out;
  // Every params struct of the library but the world's own ("params").
  std::vector<std::string> names;
  std::vector<sph_params_kind> kinds;
  for (uint32_t k = 0;; ++k) {
    sph_params_info info;
    sph_params_info_init(&info);
    if (sph_params_get_info(static_cast<sph_params_kind>(k), &info) != SPH_OK) break;
    if (k == SPH_PARAMS_WORLD) continue;
    names.push_back(info.name);
    kinds.push_back(static_cast<sph_params_kind>(k));
  }
  node.expect_object("physics", names);
  for (const std::string& key : node.keys()) {
    size_t i = 0;
    while (names[i] != key) ++i;  // expect_object let only these through
    const JsonNode section = node[key.c_str()];
    for (const sph_physics_method_info& m : library_methods())
      if (m.has_params && m.params_kind == kinds[i] && !world_runs(world, m))
        throw SceneError(section.path(), "the world does not use " + key + " (" + how_to_turn_on(m) + ")");
    PhysicsDesc d;
    d.kind = kinds[i];
    d.path = section.path();
    sph_params_info info;
    sph_params_info_init(&info);
    sph_params_get_info(d.kind, &info);
    d.bytes.assign(info.params_size, 0);
    std::memcpy(d.bytes.data(), &info.params_size, sizeof info.params_size);
    for (const sph_param_field_info& f : fields_of(d.kind)) {  // the defaults, as the _init() writes them
      if (f.type == SPH_PARAM_FLOAT || f.type == SPH_PARAM_VEC3) {
        std::memcpy(d.bytes.data() + f.offset, f.default_value, f.type == SPH_PARAM_VEC3 ? 12 : 4);
      } else {
        const uint32_t v = static_cast<uint32_t>(f.default_value[0]);
        std::memcpy(d.bytes.data() + f.offset, &v, sizeof v);
      }
    }
    parse_params_fields(section, d.kind, key.c_str(), d.bytes.data());
    out.push_back(std::move(d));
  }
  return out;
}

uint32_t parse_method(const JsonNode& node, sph_method_switch field) {
  const std::vector<sph_physics_method_info> methods = methods_switched_by(field);
  return methods[node.choice(names_of(methods))].value;
}

uint32_t parse_features(const JsonNode& node) {
  const std::vector<sph_physics_method_info> methods = methods_switched_by(SPH_METHOD_SWITCH_FEATURE);
  const std::vector<std::string> names = names_of(methods);
  uint32_t bits = 0;
  const size_t n = node.array_size("a list of feature names");
  for (size_t i = 0; i < n; ++i) bits |= methods[node.index(i).choice(names)].value;
  return bits;
}

}  // namespace sph_tools
