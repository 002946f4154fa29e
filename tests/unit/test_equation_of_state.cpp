// SPDX-License-Identifier: MIT
// The equation of state with its tension floor (src/physics/methods.h, pressure_from_density):
// both laws against their analytic values on both sides of the floor (1 - tau) rho0, for tau 0
// (the clamp at zero, compared bit for bit with the clamp as written before the floor), 0.005,
// 0.02 and the largest, 0.125; a NaN density stays NaN. Tolerance: the law evaluates in float, the
// expected values are doubles, and p is a difference of two terms: 4 ulps of the ideal gas's
// k rho; 16 ulps of Tait's larger term B max(r^7, 1) (r = rho / rho0 rounded once, then raised
// to the 7th power in four products: about 11 ulps at worst).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstring>
#include <limits>

#include "physics/methods.h"

namespace {

constexpr double kUlp = 1.2e-7;  // 2^-23
constexpr float kRho0 = 1000.0f;

sph::EosConstants eos(sph::EquationOfState kind, float tau) {
  sph::MethodParams p;
  p.ideal_gas.stiffness = 100.0f;  // c = 10 m/s
  p.tait.speed_of_sound = 12.0f;   // B = rho0 c^2 / 7
  p.wcsph.tension_ratio = tau;
  sph::MethodSelection s;
  s.equation_of_state = kind;
  sph::WorldShape shape{0.02f, 0.036f, kRho0, 8e-3f};
  return sph::make_eos_constants(p, s, shape);
}

// The laws as functions of rho alone, in double.
double ideal_gas(double rho) { return 100.0 * (rho - kRho0); }
double tait(double rho) {
  const double b = kRho0 * 12.0 * 12.0 / 7.0;
  return b * (std::pow(rho / kRho0, 7.0) - 1.0);
}
double law(sph::EquationOfState kind, double rho) {
  return kind == sph::EquationOfState::Tait ? tait(rho) : ideal_gas(rho);
}
// The tolerance: ulps of the law's larger term.
double tolerance(sph::EquationOfState kind, double rho) {
  if (kind == sph::EquationOfState::Tait)
    return 16.0 * kUlp * kRho0 * 144.0 / 7.0 * std::fmax(std::pow(rho / kRho0, 7.0), 1.0);
  return 4.0 * kUlp * 100.0 * rho;
}

void expect_law(sph::EquationOfState kind, float tau, float rho) {
  const sph::EosConstants e = eos(kind, tau);
  const double floor = (1.0 - static_cast<double>(tau)) * kRho0;
  const double at = rho < floor ? floor : rho;  // the law's argument: held at the floor below it
  const double want = law(kind, at);
  const double got = sph::pressure_from_density(e, rho);
  if (std::fabs(got - want) > tolerance(kind, at))
    fail_msg("%s, tau %g, rho %.9g: p %.9g, want %.9g",
             kind == sph::EquationOfState::Tait ? "tait" : "ideal gas", static_cast<double>(tau),
             static_cast<double>(rho), got, want);
}

// The densities that probe a floor: far below, just below and above it, rho0 itself, above.
void expect_both_sides(sph::EquationOfState kind, float tau) {
  const float floor = (1.0f - tau) * kRho0;
  const float samples[] = {0.0f,
                           0.5f * kRho0,
                           floor - 10.0f,
                           std::nextafter(floor, 0.0f),
                           floor,
                           std::nextafter(floor, 2.0f * kRho0),
                           floor + 0.5f * (kRho0 - floor),
                           kRho0,
                           1.001f * kRho0,
                           1.05f * kRho0};
  for (float rho : samples) expect_law(kind, tau, rho);
}

// The clamp as pressure_from_density wrote it before the floor (commit b6097c4).
float clamped(const sph::EosConstants& e, float density) {
  const float excess = density - e.rest_density;
  if (excess <= 0.0f) return 0.0f;
  if (e.kind == sph::EquationOfState::Tait) return sph::TaitEos::pressure(e.tait, density, e.rest_density);
  return sph::IdealGasEos::pressure(e.ideal_gas, excess);
}

void test_tau_zero_is_the_clamp_bit_for_bit(void**) {
  for (sph::EquationOfState kind : {sph::EquationOfState::IdealGas, sph::EquationOfState::Tait}) {
    const sph::EosConstants e = eos(kind, 0.0f);
    assert_true(e.tension_floor == kRho0);
    // Every float from 0.5 rho0 to 1.5 rho0 in steps of about 0.01 kg/m^3, and those around rho0.
    for (int i = -50000; i <= 50000; ++i) {
      const float rho = kRho0 * (1.0f + 1e-5f * static_cast<float>(i));
      const float got = sph::pressure_from_density(e, rho), want = clamped(e, rho);
      if (std::memcmp(&got, &want, sizeof got) != 0)
        fail_msg("rho %.9g: %.9g, the clamp %.9g", static_cast<double>(rho), static_cast<double>(got),
                 static_cast<double>(want));
    }
    float rho = kRho0;
    for (int i = 0; i < 100; ++i) rho = std::nextafter(rho, 0.0f);
    for (int i = 0; i < 200; ++i, rho = std::nextafter(rho, 2.0f * kRho0)) {
      const float got = sph::pressure_from_density(e, rho), want = clamped(e, rho);
      assert_memory_equal(&got, &want, sizeof got);
      if (rho <= kRho0) assert_true(got == 0.0f && !std::signbit(got));
    }
  }
}

void test_both_laws_on_both_sides_of_the_floor(void**) {
  for (sph::EquationOfState kind : {sph::EquationOfState::IdealGas, sph::EquationOfState::Tait})
    for (float tau : {0.0f, 0.005f, 0.02f, 0.125f}) expect_both_sides(kind, tau);
}

// The tension is bounded: never below the law at the floor (-k tau rho0 for the ideal gas), and
// it is reached: the floor's value is the law's there, not zero.
void test_the_bound_is_the_law_at_the_floor(void**) {
  const sph::EosConstants e = eos(sph::EquationOfState::IdealGas, 0.02f);
  const float at_floor = sph::pressure_from_density(e, 0.0f);
  assert_true(std::fabs(at_floor - (-100.0f * 0.02f * kRho0)) <= 4.0f * 1.2e-7f * 100.0f * kRho0);
  assert_true(sph::pressure_from_density(e, 0.9f * kRho0) == at_floor);
  assert_true(sph::pressure_from_density(e, 0.99f * kRho0) > at_floor);
  assert_true(sph::pressure_from_density(e, 0.99f * kRho0) < 0.0f);
  const sph::EosConstants t = eos(sph::EquationOfState::Tait, 0.125f);
  assert_true(sph::pressure_from_density(t, 0.0f) == sph::pressure_from_density(t, 0.5f * kRho0));
  assert_true(sph::pressure_from_density(t, 0.0f) < 0.0f);
}

void test_nan_stays_nan(void**) {
  for (sph::EquationOfState kind : {sph::EquationOfState::IdealGas, sph::EquationOfState::Tait})
    for (float tau : {0.0f, 0.02f}) {
      const float p = sph::pressure_from_density(eos(kind, tau), std::numeric_limits<float>::quiet_NaN());
      assert_true(std::isnan(p));
    }
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tau_zero_is_the_clamp_bit_for_bit),
      cmocka_unit_test(test_both_laws_on_both_sides_of_the_floor),
      cmocka_unit_test(test_the_bound_is_the_law_at_the_floor),
      cmocka_unit_test(test_nan_stays_nan),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
