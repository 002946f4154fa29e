// SPDX-License-Identifier: MIT
// Sources: a region filled with particles once or continuously, between start and stop.
#include "parse_parts.h"

namespace sph_tools {

SourceDesc parse_source(const JsonNode& node, const std::string& base_dir) {
  SourceDesc s;
  s.path = node.path();
  node.expect_object("a source", {"name", "shape", "transform", "motion", "mode", "velocity", "spacing",
                                  "min_distance", "rate", "user_attribute", "start", "stop"});
  s.name = node["name"].opt_string("");
  s.shape = parse_shape(node["shape"], base_dir);
  s.transform = parse_transform(node["transform"]);
  s.motion = parse_motion(node["motion"], s.transform);
  if (!s.motion.empty()) s.transform = s.motion.at(0.0);
  s.mode =
      node["mode"].opt_choice(0, {"once", "continuous"}) == 0 ? SPH_SOURCE_FILL_ONCE : SPH_SOURCE_CONTINUOUS;
  s.velocity = node["velocity"].opt_vec3(s.velocity);
  s.spacing = node["spacing"].opt_positive(0.0f);
  s.min_distance = node["min_distance"].opt_positive(0.0f);
  s.rate = node["rate"].opt_positive(0.0f);
  if (s.rate > 0.0f && s.mode != SPH_SOURCE_CONTINUOUS)
    node["rate"].fail("no rate for a \"once\" source (rate limits \"continuous\" sources)");
  // The world then carries a user attribute (SPH_FEATURE_USER_ATTRIBUTE; scene_parser.cpp).
  s.has_user_attribute = !node["user_attribute"].missing();
  s.user_attribute = node["user_attribute"].opt_count(0, 0, UINT32_MAX);
  parse_start_stop(node, &s.start, &s.stop);
  return s;
}

}  // namespace sph_tools
