// SPDX-License-Identifier: MIT
// Fluid bodies: boxes and spheres filled on the lattice, or explicit particles, each added at
// its time.
#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {

FluidDesc parse_fluid(const JsonNode& node) {
  FluidDesc f;
  f.path = node.path();
  if (node.missing() || !node.json().is_object()) node.fail("a fluid body (an object with a \"type\")");
  const size_t type = node["type"].choice({"box", "sphere", "particles"});
  if (type == 0) {
    node.expect_object("a box fluid", {"type", "min", "max", "velocity", "time"});
    f.kind = FluidDesc::Kind::kBox;
    f.min = node["min"].vec3();
    f.max = node["max"].vec3();
    if (!(f.max.x > f.min.x && f.max.y > f.min.y && f.max.z > f.min.z))
      node["max"].fail("a corner above min in every component");
  } else if (type == 1) {
    node.expect_object("a sphere fluid", {"type", "center", "radius", "velocity", "time"});
    f.kind = FluidDesc::Kind::kSphere;
    f.center = node["center"].vec3();
    f.radius = node["radius"].positive();
  } else {
    node.expect_object("a particle list", {"type", "positions", "velocities", "time"});
    f.kind = FluidDesc::Kind::kParticles;
    const JsonNode p = node["positions"];
    const size_t n = p.array_size("an array of [x, y, z] positions", 1);
    f.positions.reserve(3 * n);
    for (size_t i = 0; i < n; ++i) {
      const sph_vec3 v = p.index(i).vec3();
      f.positions.insert(f.positions.end(), {v.x, v.y, v.z});
    }
    if (!node["velocities"].missing()) {
      const JsonNode v = node["velocities"];
      if (v.array_size("an array of [vx, vy, vz] velocities") != n)
        v.fail("an array of " + std::to_string(n) + " velocities (one per position)");
      f.velocities.reserve(3 * n);
      for (size_t i = 0; i < n; ++i) {
        const sph_vec3 u = v.index(i).vec3();
        f.velocities.insert(f.velocities.end(), {u.x, u.y, u.z});
      }
    }
  }
  f.velocity = node["velocity"].opt_vec3(f.velocity);
  f.time = node["time"].missing() ? 0.0 : node["time"].non_negative();
  return f;
}

}  // namespace sph_tools
