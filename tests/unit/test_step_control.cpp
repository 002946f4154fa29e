// SPDX-License-Identifier: MIT
// The step controller (src/physics/step_control.h, controller_dt) with DFSPH's depth limit
// dt <= f h / sqrt(|g| H) against its analytic values: alone, under the other limits, under
// dt_min, off (factor 0, no gravity, H 0 or not finite), and H from a span (height_of_span) with
// the projection height_along on an oblique gravity. The tolerance is float rounding: the
// controller evaluates in float, the expected values are doubles (2 ulps relative, 2.4e-7).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <limits>

#include "physics/step_control.h"

namespace {

constexpr double kRelative = 2.4e-7;

sph::StepLimits limits(float factor) {
  sph::StepLimits s{};
  s.step_factor = 0.4f;
  s.kernel_radius = 0.025f;
  s.dt_min = 1e-6f;
  s.dt_max = 1.0f;
  s.sound_speed = 0.0f;
  s.use_force_limit = 0u;
  s.stability_dt = 0.0f;
  s.depth_step_factor = factor;
  s.gravity_magnitude = factor > 0.0f ? 9.81f : 0.0f;
  s.down = sph::Vec3{0.0f, -1.0f, 0.0f};
  return s;
}

void expect_near(double got, double want) {
  if (std::fabs(got - want) > kRelative * std::fabs(want)) fail_msg("got %.9g, want %.9g", got, want);
}

void depth_limit_alone(void**) {
  const sph::StepLimits s = limits(0.3f);
  for (double H : {0.01, 0.24, 0.96, 9.0}) {
    const double want = 0.3 * 0.025 / std::sqrt(9.81 * H);
    expect_near(sph::controller_dt(s, 0.0f, 0.0f, static_cast<float>(H)), want);
  }
  // 0.96 m deep at h = 2.55 cm (the 48-layer tank): 0.3 h / sqrt(g D) = 2.61 ms.
  sph::StepLimits t = s;
  t.kernel_radius = 0.0255f;
  expect_near(sph::controller_dt(t, 0.0f, 0.0f, 0.96f), 0.3 * 0.0255 / std::sqrt(9.81 * 0.96));
}

void depth_limit_with_the_others(void**) {
  sph::StepLimits s = limits(0.3f);
  const double depth = 0.3 * 0.025 / std::sqrt(9.81 * 0.5);  // 3.39 ms
  // The CFL shorter: it wins (0.4 h / 5 m/s = 2 ms); longer: the depth limit does.
  expect_near(sph::controller_dt(s, 5.0f, 0.0f, 0.5f), 0.4 * 0.025 / 5.0);
  expect_near(sph::controller_dt(s, 1.0f, 0.0f, 0.5f), depth);
  // dt_max below it wins; dt_min above it wins (a fixed step pins dt_min = dt_max).
  s.dt_max = 0.002f;
  assert_true(sph::controller_dt(s, 0.0f, 0.0f, 0.5f) == 0.002f);
  s.dt_max = 1.0f;
  s.dt_min = 0.01f;
  assert_true(sph::controller_dt(s, 0.0f, 0.0f, 0.5f) == 0.01f);
  // The stability ceiling below it wins.
  s.dt_min = 1e-6f;
  s.stability_dt = 0.001f;
  assert_true(sph::controller_dt(s, 0.0f, 0.0f, 0.5f) == 0.001f);
}

void depth_limit_off(void**) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  assert_true(sph::controller_dt(limits(0.0f), 0.0f, 0.0f, 0.5f) == 1.0f);  // off (factor 0)
  sph::StepLimits s = limits(0.3f);
  for (float H : {0.0f, -1.0f, inf, nan}) assert_true(sph::controller_dt(s, 0.0f, 0.0f, H) == 1.0f);
  s.gravity_magnitude = 0.0f;  // no gravity
  assert_true(sph::controller_dt(s, 0.0f, 0.0f, 0.5f) == 1.0f);
  // The overloads without H leave it out.
  assert_true(sph::controller_dt(limits(0.3f), 0.0f, 0.0f) == 1.0f);
  assert_true(sph::controller_dt(limits(0.3f), 0.0f) == 1.0f);
}

void height_from_a_span(void**) {
  // Gravity (3, -4, 0) / 5: the points (0, 1, 0) and (3, -3, 0) project to -0.8 and 4.2.
  sph::StepLimits s = limits(0.3f);
  s.down = sph::Vec3{0.6f, -0.8f, 0.0f};
  const float a = sph::height_along(s, sph::Vec3{0.0f, 1.0f, 0.0f});
  const float b = sph::height_along(s, sph::Vec3{3.0f, -3.0f, 0.0f});
  expect_near(a, -0.8);
  expect_near(b, 4.2);
  expect_near(sph::height_of_span(a, b), 5.0);
  assert_true(sph::height_of_span(b, a) == 0.0f);  // lo > hi: no particle
  const float inf = std::numeric_limits<float>::infinity();
  assert_true(sph::height_of_span(inf, -inf) == 0.0f);  // the empty reduction's span
  expect_near(sph::depth_step_limit(s, 5.0f), 0.3 * 0.025 / std::sqrt(9.81 * 5.0));
  assert_true(sph::depth_step_limit(s, 0.0f) == 0.0f);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(depth_limit_alone),
      cmocka_unit_test(depth_limit_with_the_others),
      cmocka_unit_test(depth_limit_off),
      cmocka_unit_test(height_from_a_span),
  };
  return cmocka_run_group_tests_name("step_control", tests, nullptr, nullptr);
}
