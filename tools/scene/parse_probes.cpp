// SPDX-License-Identifier: MIT
// Probes: points and vertical gauge lines where sph-run records the fluid per frame.
#include "parse_parts.h"

namespace sph_tools {

ProbeDesc parse_probe(const JsonNode& node) {
  ProbeDesc p;
  p.path = node.path();
  if (node.missing() || !node.json().is_object()) node.fail("a probe (an object with a \"type\")");
  const size_t type = node["type"].choice({"point", "gauge"});
  if (type == 0) {
    node.expect_object("a point probe", {"name", "type", "position", "sampling", "pressure_threshold"});
    p.kind = SPH_PROBE_POINT;
  } else {
    node.expect_object("a gauge", {"name", "type", "position", "direction", "length", "sample_spacing",
                                   "sampling", "pressure_threshold"});
    p.kind = SPH_PROBE_GAUGE;
    if (!node["direction"].missing()) p.direction = node["direction"].direction();
    p.length = node["length"].positive();
    p.sample_spacing = node["sample_spacing"].opt_positive(0.0f);
  }
  p.position = node["position"].vec3();
  p.sampling = node["sampling"].opt_choice(0, {"frame", "substep"}) == 0 ? SPH_PROBE_EVERY_FRAME
                                                                         : SPH_PROBE_EVERY_SUBSTEP;
  p.name = node["name"].opt_string("");
  p.pressure_threshold = node["pressure_threshold"].opt_non_negative(0.0f);
  return p;
}

}  // namespace sph_tools
