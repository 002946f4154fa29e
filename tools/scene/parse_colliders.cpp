// SPDX-License-Identifier: MIT
// Colliders: a shape placed in the world, its material and its keyframed motion.
#include "parse_parts.h"

namespace sph_tools {

ColliderDesc parse_collider(const JsonNode& node, const std::string& base_dir) {
  ColliderDesc c;
  c.path = node.path();
  node.expect_object("a collider", {"name", "shape", "transform", "motion", "inverted", "restitution",
                                    "friction", "stickiness", "loads"});
  c.name = node["name"].opt_string("");
  c.shape = parse_shape(node["shape"], base_dir);
  c.transform = parse_transform(node["transform"]);
  c.motion = parse_motion(node["motion"], c.transform);
  if (!c.motion.empty()) c.transform = c.motion.at(0.0);
  c.inverted = node["inverted"].opt_boolean(false);
  c.restitution = node["restitution"].opt_in_range(0.0f, 0.0f, 1.0f);
  c.friction = node["friction"].opt_non_negative(0.0f);
  c.stickiness = node["stickiness"].opt_non_negative(0.0f);
  // "loads": {"point": [x, y, z], "threshold": N} (or {}): sph-run writes the collider's loads per
  // frame to a CSV (docs/cli.md) and says when a frame's force reaches the threshold; the world
  // gets SPH_FEATURE_COLLIDER_LOADS.
  const JsonNode loads = node["loads"];
  if (!loads.missing()) {
    loads.expect_object("the collider's loads", {"point", "threshold"});
    c.loads = true;
    c.load_point = loads["point"].opt_vec3(sph_vec3{0.0f, 0.0f, 0.0f});
    c.load_threshold = loads["threshold"].opt_non_negative(0.0f);
  }
  return c;
}

}  // namespace sph_tools
