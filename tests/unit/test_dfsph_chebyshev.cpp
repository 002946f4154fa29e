// SPDX-License-Identifier: MIT
// The Chebyshev density solve's arithmetic (src/physics/dfsph_chebyshev.h, SPH_DFSPH_CHEBYSHEV), which
// both backends call: the weights against the recurrence worked in double and its closed-form limit
// w* = 2 / (1 + sqrt(1 - rho^2)) (Golub & Varga), the early stop of the weights' loop, the release of an
// expanded particle and the limit that keeps the solve's total pressure >= 0.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>

#include "physics/dfsph_chebyshev.h"

namespace {

using sph::chebyshev_step;
using sph::chebyshev_weight;
using sph::density_residual;
using sph::density_residual_released;
using sph::DfsphChebyshev;
using sph::DfsphResidual;

void test_weights_follow_the_recurrence(void**) {
  const double r2 = static_cast<double>(DfsphChebyshev::kSpectralRadius) * DfsphChebyshev::kSpectralRadius;
  assert_true(chebyshev_weight(0) == 1.0f);  // the first pass: the Jacobi step alone
  double w = 2.0 / (2.0 - r2);
  for (uint32_t n = 1; n <= 60; ++n) {
    if (n > 1) w = 4.0 / (4.0 - r2 * w);
    // float against double: a few ulps of ~1.5 after dozens of steps (each contracts errors by ~0.5).
    assert_true(std::fabs(chebyshev_weight(n) - w) <= 1e-6 * w);
    // Over-relaxation, largest at the second pass (w_1 = 2 / (2 - rho^2)), falling to its limit.
    assert_true(chebyshev_weight(n) > 1.0f);
    if (n > 1) assert_true(chebyshev_weight(n) <= chebyshev_weight(n - 1));
  }
  const double limit = 2.0 / (1.0 + std::sqrt(1.0 - r2));
  assert_true(std::fabs(chebyshev_weight(60) - limit) <= 1e-6 * limit);
}

void test_weight_loop_stops_at_its_fixed_point(void**) {
  // A cap of 4e9 iterations answers at once, with the limit's value (the loop stops where the
  // recurrence's next float equals the last).
  const float far = chebyshev_weight(4000000000u);
  assert_true(far == chebyshev_weight(1000u));
  assert_true(far == chebyshev_weight(200u));
}

void test_release_of_an_expanded_particle(void**) {
  const float rho0 = 1000.0f, dt = 1e-3f, factor = 2e-6f;
  // Compressed (rho* = 1001): the plain residual, unchanged.
  const DfsphResidual plain = density_residual(0.0f, 1001.0f, factor, rho0, dt);
  const DfsphResidual compressed = density_residual_released(0.0f, 1001.0f, factor, rho0, dt, 5.0f);
  assert_true(compressed.k == plain.k && compressed.error == plain.error);
  assert_true(plain.k > 0.0f);
  // Expanded (rho* = 999): a negative step, kRelease of the formula's, and no error.
  const DfsphResidual released = density_residual_released(0.0f, 999.0f, factor, rho0, dt, 5.0f);
  const float expected = DfsphChebyshev::kRelease * (-1.0f) * factor / (dt * dt);
  assert_true(std::fabs(released.k - expected) <= 1e-6f * std::fabs(expected));
  assert_true(released.error == 0.0f);
  // Never below the pressure held: with 0.1 held, the step is -0.1 (the formula asks -0.5).
  const DfsphResidual limited = density_residual_released(0.0f, 999.0f, factor, rho0, dt, 0.1f);
  assert_true(limited.k == -0.1f);
  // Nothing held, nothing released.
  assert_true(density_residual_released(0.0f, 999.0f, factor, rho0, dt, 0.0f).k == 0.0f);
}

void test_step_mixes_and_is_limited(void**) {
  // w = 1: the Jacobi step alone, the previous one not read (NaN would show).
  assert_true(chebyshev_step(1.0f, 2.0f, NAN, 0.0f) == 2.0f);
  // w = 1.5: 1.5 * 2 + 0.5 * 1 = 3.5.
  assert_true(chebyshev_step(1.5f, 2.0f, 1.0f, 0.0f) == 3.5f);
  // A negative mix no deeper than the pressure held: 1.5 * -4 + 0.5 * 1 = -5.5, held 3 -> -3.
  assert_true(chebyshev_step(1.5f, -4.0f, 1.0f, 3.0f) == -3.0f);
  assert_true(chebyshev_step(1.5f, -1.0f, 1.0f, 3.0f) == -1.0f);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_weights_follow_the_recurrence),
      cmocka_unit_test(test_weight_loop_stops_at_its_fixed_point),
      cmocka_unit_test(test_release_of_an_expanded_particle),
      cmocka_unit_test(test_step_mixes_and_is_limited),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
