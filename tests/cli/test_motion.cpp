// SPDX-License-Identifier: MIT
// Keyframed motion (issue 7, item 1): the pose a collider is sent each frame. Linear and smooth
// interpolation pass through their keys, hold before the first and after the last, loop, and
// turn rotations along the shorter arc; axis-angle and quaternion rotations of a scene file
// agree.
#include <cmath>
#include <string>

#include "geometry.h"
#include "motion.h"
#include "scene_parser.h"

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

namespace {

using sph_tools::Keyframe;
using sph_tools::Motion;

Keyframe key(double time, float x, float y, float degrees_about_z) {
  Keyframe k;
  k.time = time;
  k.transform.position = sph_vec3{x, y, 0.0f};
  k.transform.rotation =
      sph_tools::quat_axis_angle(sph_vec3{0, 0, 1}, degrees_about_z * 3.14159265f / 180.0f);
  return k;
}

float angle_about_z(const sph_quat& q) { return 2.0f * std::atan2(q.z, q.w) * 180.0f / 3.14159265f; }

void test_linear_passes_keys_and_holds_ends(void**) {
  Motion m;
  m.keys = {key(1.0, 0, 0, 0), key(2.0, 1, 2, 90), key(4.0, 1, 0, 90)};
  for (const Keyframe& k : m.keys) {
    const sph_transform t = m.at(k.time);
    assert_true(std::fabs(t.position.x - k.transform.position.x) < 1e-6f);
    assert_true(std::fabs(t.position.y - k.transform.position.y) < 1e-6f);
  }
  sph_transform t = m.at(1.5);
  assert_true(std::fabs(t.position.x - 0.5f) < 1e-6f && std::fabs(t.position.y - 1.0f) < 1e-6f);
  assert_true(std::fabs(angle_about_z(t.rotation) - 45.0f) < 1e-3f);
  t = m.at(3.0);
  assert_true(std::fabs(t.position.y - 1.0f) < 1e-6f);
  t = m.at(0.0);  // before the first key: the first pose
  assert_true(t.position.x == 0.0f && t.position.y == 0.0f);
  t = m.at(10.0);  // after the last: the last pose
  assert_true(t.position.x == 1.0f && t.position.y == 0.0f);
}

void test_smooth_passes_keys_without_velocity_jumps(void**) {
  Motion m;
  m.interpolation = Motion::Interpolation::kSmooth;
  m.keys = {key(0.0, 0, 0, 0), key(1.0, 1, 0, 0), key(2.0, 1, 1, 0), key(3.0, 0, 1, 0)};
  for (const Keyframe& k : m.keys) {
    const sph_transform t = m.at(k.time);
    assert_true(std::fabs(t.position.x - k.transform.position.x) < 1e-5f);
    assert_true(std::fabs(t.position.y - k.transform.position.y) < 1e-5f);
  }
  // The velocity on both sides of an inner key agrees (C1), unlike linear interpolation.
  const double h = 1e-3;
  const sph_transform a = m.at(1.0 - h), b = m.at(1.0), c = m.at(1.0 + h);
  const float left = (b.position.x - a.position.x) / static_cast<float>(h);
  const float right = (c.position.x - b.position.x) / static_cast<float>(h);
  assert_true(std::fabs(left - right) < 0.01f);
}

void test_loop_repeats_and_rotations_take_short_arc(void**) {
  Motion m;
  m.loop = true;
  m.keys = {key(0.0, 0, 0, 0), key(0.5, 1, 0, 0), key(1.0, 0, 0, 0)};
  assert_true(std::fabs(m.at(2.25).position.x - 0.5f) < 1e-5f);
  assert_true(std::fabs(m.at(3.5).position.x - 1.0f) < 1e-5f);
  Motion turn;
  turn.keys = {key(0.0, 0, 0, 170), key(1.0, 0, 0, -170)};  // 20 degrees through 180, not 340
  assert_true(std::fabs(std::fabs(angle_about_z(turn.at(0.5).rotation)) - 180.0f) < 1e-2f);
}

void test_scene_rotations_agree(void**) {
  const sph_tools::SceneDesc scene = sph_tools::parse_scene(
      R"({"colliders": [
           {"shape": {"type": "sphere", "radius": 1}, "transform": {"rotation": {"axis": [0, 0, 2], "degrees": 90}}},
           {"shape": {"type": "sphere", "radius": 1}, "transform": {"rotation": {"axis": [0, 0, 1], "radians": 1.5707963}}},
           {"shape": {"type": "sphere", "radius": 1}, "transform": {"rotation": {"quaternion": [0, 0, 1, 1]}}}]})",
      ".");
  for (const sph_tools::ColliderDesc& c : scene.colliders) {
    const sph_vec3 x = sph_tools::rotate(c.transform.rotation, sph_vec3{1, 0, 0});  // x turns to y
    assert_true(std::fabs(x.x) < 1e-6f && std::fabs(x.y - 1.0f) < 1e-6f);
  }
  // A motion's keys default to the object's transform; the collider starts at the motion's pose.
  const sph_tools::SceneDesc moving = sph_tools::parse_scene(
      R"({"colliders": [{"shape": {"type": "sphere", "radius": 1}, "transform": {"position": [5, 6, 7]},
                         "motion": {"keyframes": [{"time": 0, "position": [1, 2, 3]}, {"time": 1}]}}]})",
      ".");
  const sph_tools::ColliderDesc& c = moving.colliders[0];
  assert_true(c.transform.position.x == 1.0f && c.transform.position.z == 3.0f);
  assert_true(c.motion.keys[1].transform.position.x == 5.0f);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_linear_passes_keys_and_holds_ends),
      cmocka_unit_test(test_smooth_passes_keys_without_velocity_jumps),
      cmocka_unit_test(test_loop_repeats_and_rotations_take_short_arc),
      cmocka_unit_test(test_scene_rotations_agree),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
