// SPDX-License-Identifier: MIT
// Force fields: uniform, radial and vortex accelerations, optionally within a region.
#include "parse_parts.h"

namespace sph_tools {

ForceFieldDesc parse_force_field(const JsonNode& node, const std::string& base_dir) {
  ForceFieldDesc f;
  f.path = node.path();
  if (node.missing() || !node.json().is_object()) node.fail("a force field (an object with a \"type\")");
  const size_t type = node["type"].choice({"uniform", "radial", "vortex"});
  switch (type) {
    case 0:
      node.expect_object("a uniform field",
                         {"name", "type", "vector", "region", "transform", "motion", "start", "stop"});
      f.kind = SPH_FORCE_FIELD_UNIFORM;
      f.vector = node["vector"].vec3();
      break;
    case 1:
      node.expect_object("a radial field", {"name", "type", "strength", "falloff_radius", "region",
                                            "transform", "motion", "start", "stop"});
      f.kind = SPH_FORCE_FIELD_RADIAL;
      f.strength = static_cast<float>(node["strength"].number());
      break;
    default:
      node.expect_object("a vortex field", {"name", "type", "axis", "strength", "falloff_radius", "region",
                                            "transform", "motion", "start", "stop"});
      f.kind = SPH_FORCE_FIELD_VORTEX;
      f.vector = node["axis"].direction();
      f.strength = static_cast<float>(node["strength"].number());
      break;
  }
  f.falloff_radius = node["falloff_radius"].opt_positive(0.0f);
  f.name = node["name"].opt_string("");
  if (!node["region"].missing()) {
    f.has_region = true;
    f.region = parse_shape(node["region"], base_dir);
  }
  f.transform = parse_transform(node["transform"]);
  f.motion = parse_motion(node["motion"], f.transform);
  if (!f.motion.empty()) f.transform = f.motion.at(0.0);
  parse_start_stop(node, &f.start, &f.stop);
  return f;
}

}  // namespace sph_tools
