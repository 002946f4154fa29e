// SPDX-License-Identifier: MIT
// The density diffusion's term (src/physics/density_diffusion.h) on a random cloud of 3,000
// particles with about 40 neighbours each (the neighbour gather against a brute-force pair loop):
//
// 1. Uniform density, no gravity: every pair term is 0 x weight, so D_i is exactly zero.
// 2. The hydrostatic profile rho = rho0 (1 + g . x / c0^2) with gravity: the Fourtakas
//    correction subtracts exactly the pair's density difference, so D_i vanishes to rounding.
//    The rounding bound: rho_i and rho_j are read back as 1 / (1 / rho) (two roundings each)
//    and rho_ji - rho^H_ji cancels two numbers of size |rho| into one of size ~0, so each
//    dynamic difference is wrong by at most ~8 u rho_max (u = 2^-24); the bound is 16 u rho_max
//    sum_j |weight_j| (weight_j: the pair term per unit density difference). The same field
//    without the correction (Molteni & Colagrossi's plain term) must read far above it, so the
//    check can fail.
// 3. Conservation: sum_i V_i D_i = 0 (V_i = m / rho_i), each pair's two terms cancel up to the
//    rounding of V_i / rho_j against V_j / rho_i; bound 4 (K + 2) u sum_i V_i sum_j |t_ij|
//    (K the largest neighbour count; Higham's recursive-summation bound, one extra for the
//    products) on a random density field with gravity on.
// 4. Sign: a single particle denser than its uniform neighbours loses density, they gain.
// 5. The CPU backend's SIMD gather (every target this processor runs) against the scalar one:
//    the same terms in another order, within 2 (K + 1) u sum_j |t_ij| (as test_simd_passes).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/config.h"
#include "cpu/cpu_neighbor_columns.h"
#include "cpu/cpu_neighbor_grid.h"
#include "cpu/cpu_simd_passes.h"
#include "physics/density_diffusion.h"

namespace {

using sph::Float4;
using sph::Vec3;

constexpr float kH = 0.036f;  // 1.8 x the default 2 cm spacing
constexpr double kUnitRoundoff = 1.0 / 16777216.0;
constexpr float kRho0 = 1000.0f;

struct Cloud {
  sph::WorldConfig config;
  sph::CpuNeighborGrid grid{kH, UINT32_MAX};
  std::vector<Float4> positions, velocities;  // sorted; velocities[i].w = 1 / rho_i
  uint32_t n = 0;

  explicit Cloud(uint32_t seed) {
    config.kernel_radius = kH;
    config.rest_density = kRho0;
    config.particle_spacing = kH / 1.8f;
    config.particle_mass = 0.0056569f;
    config.density_self_weight = 60000.0f;
    config.features = sph::kFeatureNormalizedDensity | sph::kFeatureDensityDiffusion;
    n = 3000;
    const float half = 0.5f * std::cbrt(3000.0f * 4.18879f * kH * kH * kH / 40.0f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-half, half);
    std::vector<Float4> records(n);
    for (Float4& r : records) r = sph::make_float4_record(Vec3{u(rng), u(rng), u(rng)}, 0.0f);
    grid.build(records.data(), n, 1);
    positions.resize(n);
    velocities.resize(n);
    for (uint32_t i = 0; i < n; ++i) positions[i] = records[grid.order()[i]];
  }

  template <class Density>
  void set_density(Density&& rho_of) {
    for (uint32_t i = 0; i < n; ++i)
      velocities[i] = Float4{0.0f, 0.0f, 0.0f, 1.0f / rho_of(i, xyz(positions[i]))};
  }

  sph::FluidConstants fluid(Vec3 gravity, float delta = 0.1f) {
    sph::RuntimeParams params;
    params.stepping.gravity = gravity;
    params.methods.density_diffusion.delta = delta;
    return sph::make_fluid_constants(config, params);
  }

  float gather(const sph::FluidConstants& f, uint32_t i) const {
    return sph::gather_density_diffusion(f, f.methods.density_diffusion, grid.view(), positions.data(),
                                         velocities.data(), i);
  }

  // The brute-force pair loop: D_i, sum_j |t_ij| and sum_j |weight_ij| (the term per unit
  // density difference, without the correction), and the neighbour count.
  struct Brute {
    double rate = 0.0, abs_terms = 0.0, abs_weights = 0.0;
    uint32_t neighbors = 0;
  };
  Brute brute(const sph::FluidConstants& f, uint32_t i) const {
    Brute b;
    sph::DensityDiffusion::Constants plain = f.methods.density_diffusion;
    plain.hydrostatic = Vec3{0.0f, 0.0f, 0.0f};
    const Vec3 xi = xyz(positions[i]);
    const float rho_i = 1.0f / velocities[i].w;
    for (uint32_t j = 0; j < n; ++j) {
      const Vec3 x_ji = xyz(positions[j]) - xi;
      const float r2 = sph::length_squared(x_ji);
      if (r2 >= f.kernel.h2 || j == i) continue;
      const float r = std::sqrt(r2);
      const float inv_rho_j = velocities[j].w;
      const float t = sph::density_diffusion_pair_term(f, f.methods.density_diffusion, x_ji, r,
                                                       1.0f / inv_rho_j - rho_i, inv_rho_j);
      b.rate += t;
      b.abs_terms += std::fabs(t);
      b.abs_weights += std::fabs(sph::density_diffusion_pair_term(f, plain, x_ji, r, 1.0f, inv_rho_j));
      ++b.neighbors;
    }
    return b;
  }
};

void test_uniform_density_is_left_alone(void**) {
  Cloud c(1);
  c.set_density([](uint32_t, Vec3) { return kRho0; });
  const sph::FluidConstants f = c.fluid(Vec3{0.0f, 0.0f, 0.0f});
  uint32_t with_neighbors = 0;
  for (uint32_t i = 0; i < c.n; ++i) {
    assert_true(c.gather(f, i) == 0.0f);
    with_neighbors += c.brute(f, i).neighbors > 20;
  }
  assert_true(with_neighbors > c.n / 2);  // the cloud is dense enough to have pairs at all
}

void test_hydrostatic_profile_is_left_alone(void**) {
  Cloud c(2);
  const Vec3 g{0.0f, -9.81f, 0.0f};
  const sph::FluidConstants f = c.fluid(g);
  const float c0 = sph::speed_of_sound(f.methods.eos);  // the ideal-gas law's sqrt(k) = 10 m/s
  assert_true(std::fabs(c0 - 10.0f) < 1e-4f);
  // rho = rho0 (1 + g . x / c0^2), computed in double, one rounding to float.
  c.set_density([&](uint32_t, Vec3 x) {
    return static_cast<float>(kRho0 * (1.0 + (static_cast<double>(g.y) * x.y) / (c0 * c0)));
  });
  double rho_max = 0.0;
  for (uint32_t i = 0; i < c.n; ++i) rho_max = std::fmax(rho_max, 1.0 / c.velocities[i].w);
  sph::DensityDiffusion::Constants plain = f.methods.density_diffusion;
  plain.hydrostatic = Vec3{0.0f, 0.0f, 0.0f};
  double worst_ratio = 0.0, plain_max = 0.0;
  for (uint32_t i = 0; i < c.n; ++i) {
    const Cloud::Brute b = c.brute(f, i);
    if (b.neighbors < 20) continue;  // the cloud's rim: lopsided in every direction
    const double bound = 16.0 * kUnitRoundoff * rho_max * b.abs_weights;
    const double corrected = c.gather(f, i);
    const double uncorrected =
        sph::gather_density_diffusion(f, plain, c.grid.view(), c.positions.data(), c.velocities.data(), i);
    worst_ratio = std::fmax(worst_ratio, std::fabs(corrected) / bound);
    plain_max = std::fmax(plain_max, std::fabs(uncorrected) / bound);
  }
  std::printf(
      "hydrostatic profile: |D_i| at most %.3f of the rounding bound; the plain term up to %.0f x it\n",
      worst_ratio, plain_max);
  assert_true(worst_ratio <= 1.0);
  // The plain term is not zero on the profile wherever a neighbourhood is lopsided in y: it must
  // read far above the bound somewhere, or the check above proves nothing.
  assert_true(plain_max >= 100.0);
}

void test_volume_weighted_sum_is_zero(void**) {
  Cloud c(3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> density(900.0f, 1100.0f);
  c.set_density([&](uint32_t, Vec3) { return density(rng); });
  const sph::FluidConstants f = c.fluid(Vec3{0.0f, -9.81f, 0.0f});
  double sum = 0.0, abs_sum = 0.0;
  uint32_t most = 0;
  for (uint32_t i = 0; i < c.n; ++i) {
    const Cloud::Brute b = c.brute(f, i);
    const double volume = static_cast<double>(c.config.particle_mass) * c.velocities[i].w;
    const float d = c.gather(f, i);
    // The gather finds every pair the brute loop does: the same terms in another order.
    assert_true(std::fabs(d - b.rate) <= 2.0 * (b.neighbors + 1) * kUnitRoundoff * b.abs_terms + 1e-30);
    sum += volume * d;
    abs_sum += volume * b.abs_terms;
    if (b.neighbors > most) most = b.neighbors;
  }
  const double bound = 4.0 * (most + 2) * kUnitRoundoff * abs_sum;
  std::printf("sum_i V_i D_i = %.3e against sum_i V_i sum_j |t_ij| = %.3e (bound %.3e, K = %u)\n", sum,
              abs_sum, bound, most);
  assert_true(abs_sum > 0.0);
  assert_true(std::fabs(sum) <= bound);
}

void test_simd_gather_matches_the_scalar_one(void**) {
  Cloud c(5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> density(950.0f, 1050.0f);
  c.set_density([&](uint32_t, Vec3) { return density(rng); });
  const sph::FluidConstants f = c.fluid(Vec3{0.0f, -9.81f, 0.0f});
  sph::CpuNeighborColumns columns{false, false};
  columns.resize(c.n);
  columns.copy_state(c.positions.data(), c.velocities.data(), 0, c.n);
  for (uint32_t i = 0; i < c.n; ++i) columns.set_density(i, 0.0f, c.velocities[i].w);
  uint32_t targets = 0;
  for (sph::SimdTarget t : {sph::SimdTarget::Generic, sph::SimdTarget::Avx2, sph::SimdTarget::Avx512}) {
    const sph::SimdPasses* passes = sph::simd_passes_built(t);
    if (!passes || !sph::simd_target_runs(t)) continue;
    ++targets;
    for (uint32_t i = 0; i < c.n; ++i) {
      const Cloud::Brute b = c.brute(f, i);
      const float lanes = passes->density_diffusion(f, c.grid.view(), columns.view(), i);
      assert_true(std::fabs(lanes - c.gather(f, i)) <= 2.0 * (b.neighbors + 1) * kUnitRoundoff * b.abs_terms);
    }
  }
  assert_true(targets >= 1);
}

void test_a_dense_particle_spreads_its_excess(void**) {
  Cloud c(4);
  const uint32_t centre = c.n / 2;
  c.set_density([&](uint32_t i, Vec3) { return i == centre ? 1010.0f : kRho0; });
  const sph::FluidConstants f = c.fluid(Vec3{0.0f, 0.0f, 0.0f});
  assert_true(c.gather(f, centre) < 0.0f);
  const Vec3 xc = xyz(c.positions[centre]);
  for (uint32_t i = 0; i < c.n; ++i) {
    if (i == centre) continue;
    const float r2 = sph::length_squared(xyz(c.positions[i]) - xc);
    const float d = c.gather(f, i);
    if (r2 < f.kernel.h2) {
      assert_true(d > 0.0f);
    } else {
      assert_true(d == 0.0f);
    }
  }
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uniform_density_is_left_alone),
      cmocka_unit_test(test_hydrostatic_profile_is_left_alone),
      cmocka_unit_test(test_volume_weighted_sum_is_zero),
      cmocka_unit_test(test_a_dense_particle_spreads_its_excess),
      cmocka_unit_test(test_simd_gather_matches_the_scalar_one),
  };
  return cmocka_run_group_tests_name("density_diffusion", tests, nullptr, nullptr);
}
