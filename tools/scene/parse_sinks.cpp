// SPDX-License-Identifier: MIT
// Sinks: a region, or everything outside a box, where particles are removed.
#include "parse_parts.h"

namespace sph_tools {

SinkDesc parse_sink(const JsonNode& node, const std::string& base_dir) {
  SinkDesc s;
  s.path = node.path();
  if (node.missing() || !node.json().is_object()) node.fail("a sink (an object with a \"type\")");
  const size_t type = node["type"].choice({"region", "outside_bounds"});
  if (type == 0) {
    node.expect_object("a region sink", {"name", "type", "shape", "transform"});
    s.mode = SPH_SINK_REGION;
    s.shape = parse_shape(node["shape"], base_dir);
    s.transform = parse_transform(node["transform"]);
  } else {
    node.expect_object("an outside_bounds sink", {"name", "type", "min", "max"});
    s.mode = SPH_SINK_OUTSIDE_BOUNDS;
    s.transform = parse_transform(JsonNode(nullptr, ""));
    s.bounds_min = node["min"].vec3();
    s.bounds_max = node["max"].vec3();
    if (!(s.bounds_max.x > s.bounds_min.x && s.bounds_max.y > s.bounds_min.y &&
          s.bounds_max.z > s.bounds_min.z))
      node["max"].fail("a corner above min in every component");
  }
  s.name = node["name"].opt_string("");
  return s;
}

}  // namespace sph_tools
