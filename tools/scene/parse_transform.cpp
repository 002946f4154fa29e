// SPDX-License-Identifier: MIT
// Rotations, transforms and keyframed motion of a scene file.
#include <cmath>

#include "geometry.h"
#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {

sph_quat parse_rotation(const JsonNode& node) {
  node.expect_object("a rotation", {"axis", "degrees", "radians", "quaternion"});
  if (node.has("quaternion")) {
    if (node.has("axis") || node.has("degrees") || node.has("radians"))
      throw SceneError(node.path(),
                       "give either \"quaternion\" or \"axis\" with \"degrees\"/\"radians\", not both");
    const JsonNode q = node["quaternion"];
    if (!q.json().is_array() || q.json().size() != 4) q.fail("an array of 4 numbers [x, y, z, w]");
    const float x = static_cast<float>(q.index(0).number()), y = static_cast<float>(q.index(1).number()),
                z = static_cast<float>(q.index(2).number()), w = static_cast<float>(q.index(3).number());
    if (x == 0.0f && y == 0.0f && z == 0.0f && w == 0.0f) q.fail("a non-zero quaternion [x, y, z, w]");
    return quat_normalize(sph_quat{x, y, z, w});
  }
  const JsonNode axis = node["axis"];
  if (axis.missing())
    throw SceneError(node.path(), "expected \"quaternion\" or \"axis\" with \"degrees\" or \"radians\"");
  const sph_vec3 a = axis.direction();
  if (node.has("degrees") == node.has("radians"))
    throw SceneError(node.path(), "an axis rotation needs exactly one of \"degrees\" or \"radians\"");
  const float radians = node.has("degrees")
                            ? static_cast<float>(node["degrees"].number() * 3.14159265358979323846 / 180.0)
                            : static_cast<float>(node["radians"].number());
  return quat_axis_angle(a, radians);
}

sph_transform parse_transform(const JsonNode& node) {
  sph_transform t{sph_vec3{0.0f, 0.0f, 0.0f}, quat_identity()};
  if (node.missing()) return t;
  node.expect_object("a transform", {"position", "rotation"});
  t.position = node["position"].opt_vec3(t.position);
  if (node.has("rotation")) t.rotation = parse_rotation(node["rotation"]);
  return t;
}

Motion parse_motion(const JsonNode& node, const sph_transform& base) {
  Motion motion;
  if (node.missing()) return motion;
  node.expect_object("a motion", {"keyframes", "interpolation", "loop"});
  const JsonNode keys = node["keyframes"];
  const size_t n = keys.array_size("keyframes", 1);
  for (size_t i = 0; i < n; ++i) {
    const JsonNode k = keys.index(i);
    k.expect_object("a keyframe", {"time", "position", "rotation"});
    Keyframe key;
    key.time = k["time"].number();
    if (i > 0 && !(key.time > motion.keys.back().time))
      k["time"].fail("a time greater than the previous keyframe's (" + number_text(motion.keys.back().time) +
                     ")");
    key.transform.position = k["position"].opt_vec3(base.position);
    key.transform.rotation = k.has("rotation") ? parse_rotation(k["rotation"]) : base.rotation;
    motion.keys.push_back(key);
  }
  motion.interpolation = node["interpolation"].opt_choice(0, {"linear", "smooth"}) == 0
                             ? Motion::Interpolation::kLinear
                             : Motion::Interpolation::kSmooth;
  motion.loop = node["loop"].opt_boolean(false);
  if (motion.loop && n < 2) node["loop"].fail("false (a looping motion needs at least 2 keyframes)");
  return motion;
}

void parse_start_stop(const JsonNode& node, double* start, double* stop) {
  *start = node["start"].missing() ? 0.0 : node["start"].non_negative();
  if (!node["stop"].missing()) {
    *stop = node["stop"].number();
    if (!(*stop > *start)) node["stop"].fail("a time after start (" + number_text(*start) + " s)");
  }
}

}  // namespace sph_tools
