// SPDX-License-Identifier: MIT
// The CPU backend's SIMD passes (src/cpu/cpu_simd_passes.h) against the scalar gathers of the
// shared physics (density.h, density_normalization.h, surface_tension.h, forces.h, and DFSPH's
// dfsph_passes.h with and without the walls' share), on random
// neighbourhoods: uniform clouds with about 40 neighbours per particle, one that folds onto a
// small wrapped table (far candidates in every run), coincident particles (r = 0 between two
// different particles) and a dense knot (runs longer than 16 candidates).
//
// 1. Every target this processor runs (AVX-512, AVX2, generic) gives the same bits as the
//    generic target: the lanes' sums and their tree are fixed, so the results may not depend
//    on the instruction set.
// 2. Each SIMD result is the scalar gather's within float rounding: both add the same terms,
//    bit for bit, only in another order. Recursive summation of n terms in any order is within
//    (n - 1) u sum |t_k| of the exact sum (u = 2^-24; Higham, "Accuracy and Stability of
//    Numerical Algorithms", 2nd ed., eq. 4.4), so two orders differ by at most 2 (n - 1) u
//    sum |t_k|; the bound used is 4 (n + 1) u sum |t_k| for the rounding of the final scaling
//    (finish) as well. The neighbour counts are equal. DFSPH's factor 1 / D, D = |sum_j g_j|^2 +
//    sum_j |g_j|^2 (g_j = m grad W_ij), is bounded through its sums (test_dfsph_passes).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "core/config.h"
#include "core/grid_layout.h"
#include "cpu/cpu_neighbor_columns.h"
#include "cpu/cpu_neighbor_grid.h"
#include "cpu/cpu_simd_passes.h"
#include "physics/density.h"
#include "physics/density_normalization.h"
#include "physics/dfsph_passes.h"
#include "physics/forces.h"
#include "physics/surface_tension.h"

namespace {

using sph::Float4;
using sph::Vec3;

constexpr float kH = 0.036f;                        // 1.8 x the default 2 cm spacing
constexpr double kUnitRoundoff = 1.0 / 16777216.0;  // 2^-24

// A sorted random neighbourhood with every input of the passes, as records and as columns.
struct Scene {
  sph::WorldConfig config;
  sph::CpuNeighborGrid grid;
  std::vector<Float4> positions, velocities, normals;
  std::vector<uint32_t> counts;
  sph::CpuNeighborColumns columns{true, true};
  uint32_t n = 0;

  // The grid sizes its table by the particles' extent at each build; no crowded-cell cap here.
  Scene(const std::vector<Vec3>& points, uint32_t seed) : grid(kH, UINT32_MAX) {
    config.kernel_radius = kH;
    config.rest_density = 1000.0f;
    config.particle_spacing = kH / 1.8f;
    config.particle_mass = 0.0056569f;
    config.density_self_weight = 60000.0f;
    n = static_cast<uint32_t>(points.size());
    std::vector<Float4> records(n);
    for (uint32_t i = 0; i < n; ++i) records[i] = sph::make_float4_record(points[i], 0.0f);
    grid.build(records.data(), n, 1);
    // Inputs the passes only read: pressures, densities, velocities, counts and colour normals
    // in the ranges a fluid has (some normals below the stress threshold of 0.2 / h).
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pressure(0.0f, 200.0f), density(900.0f, 1100.0f),
        speed(-0.2f, 0.2f), normal(-20.0f, 20.0f);
    std::uniform_int_distribution<uint32_t> count(1, 60);
    positions.resize(n);
    velocities.resize(n);
    normals.resize(n);
    counts.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
      positions[i] = records[grid.order()[i]];
      positions[i].w = pressure(rng);
      velocities[i] = Float4{speed(rng), speed(rng), speed(rng), 1.0f / density(rng)};
      const Vec3 nv{normal(rng), normal(rng), normal(rng)};
      normals[i] = sph::make_float4_record(nv, sph::length(nv));
      counts[i] = count(rng);
    }
    columns.resize(n);
    columns.copy_state(positions.data(), velocities.data(), 0, n);
    for (uint32_t i = 0; i < n; ++i) {
      columns.set_density(i, positions[i].w, velocities[i].w);
      columns.set_neighbor_count(i, counts[i]);
      columns.set_normal(i, normals[i]);
    }
  }

  sph::FluidConstants fluid(const sph::MethodSelection& s) {
    config.features = s.features;
    config.viscosity_method = s.viscosity;
    sph::RuntimeParams params;
    params.stepping.gravity = Vec3{0.0f, 0.0f, 0.0f};  // so that a particle without neighbours has a = 0
    params.methods.clavet.quadratic = 0.5f;
    sph::FluidConstants f = sph::make_fluid_constants(config, params);
    f.dt = 1e-3f;
    return f;
  }

  sph::GridView view() const { return grid.view(); }
  sph::ForceInputs inputs() const {
    return sph::ForceInputs{positions.data(), velocities.data(), counts.data(), normals.data()};
  }
};

std::vector<Vec3> uniform_cloud(uint32_t count, Vec3 center, float half, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-half, half);
  std::vector<Vec3> p(count);
  for (Vec3& v : p) v = Vec3{center.x + u(rng), center.y + u(rng), center.z + u(rng)};
  return p;
}

// The clouds: about 40 neighbours inside (n / V = 40 / (4/3 pi h^3)).
std::vector<std::vector<Vec3>> clouds() {
  std::vector<std::vector<Vec3>> out;
  const float half = 0.5f * std::cbrt(3000.0f * 4.18879f * kH * kH * kH / 40.0f);
  out.push_back(uniform_cloud(3000, Vec3{0.0f, 0.0f, 0.0f}, half, 1));
  out.push_back(uniform_cloud(3000, Vec3{-3.1f, 2.7f, 1e3f}, half, 2));  // far from the origin
  std::vector<Vec3> knot = uniform_cloud(1500, Vec3{0.5f, 0.5f, 0.5f}, half, 3);
  std::vector<Vec3> dense = uniform_cloud(300, Vec3{0.5f, 0.5f, 0.5f}, 0.3f * kH, 4);
  knot.insert(knot.end(), dense.begin(), dense.end());
  for (int k = 0; k < 40; ++k) knot.push_back(knot[static_cast<size_t>(k) * 7]);  // coincident pairs
  out.push_back(knot);
  return out;
}

std::vector<const sph::SimdPasses*> runnable_targets() {
  std::vector<const sph::SimdPasses*> t;
  for (sph::SimdTarget target : {sph::SimdTarget::Generic, sph::SimdTarget::Avx2, sph::SimdTarget::Avx512}) {
    if (sph::simd_target_runs(target))
      t.push_back(sph::simd_passes_built(target));
    else if (sph::simd_passes_built(target))
      std::printf("  target %u built, not run by this processor\n", static_cast<unsigned>(target));
  }
  return t;
}

// |a - b| within 4 (n + 1) u scale, printing the first failures.
bool within_rounding(double a, double b, double scale, uint32_t n, const char* what, uint32_t i) {
  const double bound = 4.0 * (n + 1) * kUnitRoundoff * scale;
  if (std::fabs(a - b) <= bound) return true;
  std::printf("  %s of particle %u: SIMD %.9g, scalar %.9g, bound %.3g (%u neighbours)\n", what, i, a, b,
              bound, n);
  return false;
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

void test_density_passes(void**) {
  const std::vector<std::vector<Vec3>> all = clouds();
  const std::vector<const sph::SimdPasses*> targets = runnable_targets();
  for (size_t c = 0; c < all.size(); ++c) {
    Scene s(all[c], static_cast<uint32_t>(10 + c));
    const sph::FluidConstants f = s.fluid(sph::MethodSelection{});
    const sph::GridView view = s.view();
    const sph::NeighborColumns columns = s.columns.view();
    size_t failures = 0, pairs = 0;
    for (uint32_t i = 0; i < s.n; ++i) {
      const sph::DensitySample scalar = sph::gather_density(f, view, s.positions.data(), i);
      const float normalized_scalar =
          sph::gather_normalized_density(f, view, s.positions.data(), s.velocities.data(), i);
      const Float4 normal_scalar =
          sph::gather_colour_normal(f, view, s.positions.data(), s.velocities.data(), i);
      // sum |t| of the colour normal's terms, per component, in the scalar's own float terms.
      double scale[3] = {0.0, 0.0, 0.0};
      const Vec3 xi = sph::xyz(s.positions[i]);
      sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
        const Vec3 d = xi - sph::xyz(s.positions[j]);
        const float r2 = sph::length_squared(d);
        if (r2 >= f.kernel.h2 || j == i) return;
        const Vec3 t = sph::colour_normal_pair_term(f, d, r2) * f.particle_mass;
        scale[0] += std::fabs(t.x);
        scale[1] += std::fabs(t.y);
        scale[2] += std::fabs(t.z);
      });
      pairs += scalar.neighbor_count;
      const sph::SimdPasses& generic = *targets.front();
      const sph::DensitySample simd = generic.density(f, view, columns, i);
      const float normalized = generic.normalized_density(f, view, columns, i);
      const Float4 normal = generic.colour_normal(f, view, columns, i);
      const uint32_t nb = scalar.neighbor_count;
      bool ok = simd.neighbor_count == nb;
      // Positive terms: sum |t| is the sum itself (self weight included in the scaling).
      ok = within_rounding(simd.density, scalar.density, scalar.density, nb, "density", i) && ok;
      // A ratio of two positive sums over n + 1 terms each: twice the bound of one.
      ok = within_rounding(normalized, normalized_scalar, 2.0 * normalized_scalar, nb + 1, "eq. 31", i) && ok;
      ok = within_rounding(normal.x, normal_scalar.x, scale[0], nb, "normal x", i) && ok;
      ok = within_rounding(normal.y, normal_scalar.y, scale[1], nb, "normal y", i) && ok;
      ok = within_rounding(normal.z, normal_scalar.z, scale[2], nb, "normal z", i) && ok;
      ok =
          within_rounding(normal.w, normal_scalar.w, scale[0] + scale[1] + scale[2], nb, "|normal|", i) && ok;
      for (const sph::SimdPasses* t : targets) {
        const bool same = same_bits(t->density(f, view, columns, i), simd) &&
                          same_bits(t->normalized_density(f, view, columns, i), normalized) &&
                          same_bits(t->colour_normal(f, view, columns, i), normal);
        if (!same && failures < 5) std::printf("  %s differs from generic at particle %u\n", t->name, i);
        ok = ok && same;
      }
      if (!ok) ++failures;
    }
    std::printf("cloud %zu: %u particles, %.1f neighbours each, %zu targets, %zu mismatches\n", c, s.n,
                static_cast<double>(pairs) / s.n, targets.size(), failures);
    assert_true(pairs > 20u * s.n);  // dense enough that runs have many neighbours
    assert_int_equal(failures, 0);
  }
}

// Particle i's acceleration from neighbour j alone (A_0 = 0: no gravity, no neighbour).
template <class Terms, bool kPressure>
Vec3 single_pair_acceleration(const sph::FluidConstants& f, const sph::ForceInputs& in, uint32_t i,
                              uint32_t j) {
  sph::AccelerationGather<Terms, kPressure> gather(in, i);
  const Float4 pj = in.positions[j];
  const Vec3 d = gather.position() - sph::xyz(pj);
  gather.add(f, j, pj, d, sph::length_squared(d));
  return gather.finish(f);
}

// pressure: the weakly compressible gather, or DFSPH's without the pressure force.
template <bool kPressure>
void check_forces(const sph::MethodSelection& selection, const char* name) {
  const std::vector<std::vector<Vec3>> all = clouds();
  const std::vector<const sph::SimdPasses*> targets = runnable_targets();
  for (size_t c = 0; c < all.size(); ++c) {
    Scene s(all[c], static_cast<uint32_t>(20 + c));
    const sph::FluidConstants f = s.fluid(selection);
    const sph::GridView view = s.view();
    const sph::NeighborColumns columns = s.columns.view();
    const sph::ForceInputs in = s.inputs();
    std::vector<sph::SimdPasses::AccelerationFn> simd;
    for (const sph::SimdPasses* t : targets)
      simd.push_back(kPressure ? t->acceleration_for(selection)
                               : t->acceleration_without_pressure_for(selection));
    size_t failures = 0;
    for (uint32_t i = 0; i < s.n; ++i) {
      Vec3 scalar{0.0f, 0.0f, 0.0f};
      double scale[3] = {0.0, 0.0, 0.0};
      uint32_t nb = 0;
      sph::with_force_terms(selection, [&](auto terms) {
        using Terms = decltype(terms);
        scalar = sph::gather_acceleration<Terms, kPressure>(f, view, in, i);
        const Vec3 xi = sph::xyz(s.positions[i]);
        sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
          if (!sph::is_force_neighbor(f, sph::length_squared(xi - sph::xyz(s.positions[j])), i, j)) return;
          const Vec3 a = single_pair_acceleration<Terms, kPressure>(f, in, i, j);
          scale[0] += std::fabs(a.x);
          scale[1] += std::fabs(a.y);
          scale[2] += std::fabs(a.z);
          ++nb;
        });
      });
      const Vec3 a = simd.front()(f, view, columns, i);
      bool ok = within_rounding(a.x, scalar.x, scale[0], nb, "a.x", i);
      ok = within_rounding(a.y, scalar.y, scale[1], nb, "a.y", i) && ok;
      ok = within_rounding(a.z, scalar.z, scale[2], nb, "a.z", i) && ok;
      for (size_t t = 1; t < simd.size(); ++t) {
        const bool same = same_bits(simd[t](f, view, columns, i), a);
        if (!same && failures < 5)
          std::printf("  %s differs from generic at particle %u\n", targets[t]->name, i);
        ok = ok && same;
      }
      if (!ok) ++failures;
    }
    std::printf("%s%s, cloud %zu: %u particles, %zu targets, %zu mismatches\n", name,
                kPressure ? "" : " (DFSPH: no pressure force)", c, s.n, targets.size(), failures);
    assert_int_equal(failures, 0);
  }
}

void test_forces_mueller(void**) {
  check_forces<true>(sph::MethodSelection{}, "pressure + Mueller");
  check_forces<false>(sph::MethodSelection{}, "Mueller");
}

void test_forces_clavet(void**) {
  sph::MethodSelection s;
  s.viscosity = sph::ViscosityMethod::Clavet;
  check_forces<true>(s, "pressure + Clavet");
  check_forces<false>(s, "Clavet");
}

void test_forces_surface_tension(void**) {
  sph::MethodSelection s;
  s.features = sph::kFeatureSurfaceTension;
  check_forces<true>(s, "pressure + Mueller + surface tension");
  check_forces<false>(s, "Mueller + surface tension");
  s.viscosity = sph::ViscosityMethod::Clavet;
  check_forces<true>(s, "pressure + Clavet + surface tension");
  check_forces<false>(s, "Clavet + surface tension");
}

// DFSPH's three gathers (dfsph_passes.h) against their scalar twins, without walls and with a
// random walls' share (density, gradient and flux in the ranges a density map gives at 2 cm:
// |grad rho_b| up to rho0 / h, about m |grad W| of one close pair).
//
// The density, the rate and the velocity change are sums of the same float terms: the bound of
// the file's header. The factor 1 / D: each component G_c of G = sum_j g_j + grad rho_b is off
// by at most e_c = 4 (n + 1) u sum_j |g_jc| and the sum of squares S by e_S = 4 (n + 1) u S, so
// D = |G|^2 + S by at most sum_c (2 |G_c| + e_c) e_c + e_S, plus 8 u D for the rounding of
// |G|^2 + S on each side; 1 / D then within that share of D (and 2 u for the division).
void check_dfsph(bool walls) {
  const std::vector<std::vector<Vec3>> all = clouds();
  const std::vector<const sph::SimdPasses*> targets = runnable_targets();
  const float dt = 1e-3f;
  for (size_t c = 0; c < all.size(); ++c) {
    Scene s(all[c], static_cast<uint32_t>(30 + c));
    const sph::FluidConstants f = s.fluid(sph::MethodSelection{});
    const sph::KernelCoefficients mk = sph::mass_gradient_kernel(f);
    const sph::GridView view = s.view();
    const sph::NeighborColumns columns = s.columns.view();
    // k = p / rho^2 of an iteration (0 to a few 1e-4 in a dam break at 2 cm), padded as a column.
    std::mt19937 rng(static_cast<uint32_t>(40 + c));
    std::uniform_real_distribution<float> k_of(0.0f, 1e-3f), density(0.0f, 500.0f), gradient(-3e4f, 3e4f),
        flux(-50.0f, 50.0f);
    std::vector<float> k(s.n + sph::kLanePadding, 0.0f);
    for (uint32_t i = 0; i < s.n; ++i) k[i] = k_of(rng);
    std::vector<sph::BoundaryShare> shares(s.n, sph::no_boundary_share());
    std::vector<Float4> records(s.n);
    for (uint32_t i = 0; i < s.n; ++i) {
      if (walls && i % 3 != 0)
        shares[i] =
            sph::BoundaryShare{density(rng), Vec3{gradient(rng), gradient(rng), gradient(rng)}, flux(rng)};
      records[i] = sph::pack_boundary(shares[i]);
    }
    const sph::DfsphWalls dfsph_walls{walls ? records.data() : nullptr};
    size_t failures = 0, pairs = 0;
    for (uint32_t i = 0; i < s.n; ++i) {
      const sph::DfsphDensitySample scalar =
          sph::gather_density_and_factor(f, view, s.positions.data(), shares[i], i);
      const float rate_scalar =
          sph::density_rate(f, view, s.positions.data(), s.velocities.data(), dfsph_walls, i);
      const Vec3 change_scalar =
          sph::pressure_velocity_change<false>(f, view, s.positions.data(), k.data(), dfsph_walls, i, dt);
      // The terms' magnitudes, from the scalar's own float terms.
      double g_abs[3] = {0.0, 0.0, 0.0}, g_sum[3] = {0.0, 0.0, 0.0}, squares = 0.0, rate_abs = 0.0;
      double change_abs[3] = {0.0, 0.0, 0.0};
      const Vec3 xi = sph::xyz(s.positions[i]);
      const Vec3 vi = sph::xyz(s.velocities[i]);
      sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
        const Vec3 d = xi - sph::xyz(s.positions[j]);
        const float r2 = sph::length_squared(d);
        if (r2 >= f.kernel.h2 || j == i) return;
        const sph::DfsphFactorTermsOf<float> t = sph::dfsph_factor_pair_terms(f, mk, d, r2);
        const float g[3] = {t.gradient.x, t.gradient.y, t.gradient.z};
        for (int a = 0; a < 3; ++a) {
          g_abs[a] += std::fabs(g[a]);
          g_sum[a] += g[a];
        }
        squares += t.square;
        rate_abs += std::fabs(sph::density_rate_pair_term(mk, d, r2, vi - sph::xyz(s.velocities[j])));
        const Vec3 dv = sph::pressure_velocity_pair_term(mk, d, r2, k[i] + k[j]);
        change_abs[0] += std::fabs(dv.x);
        change_abs[1] += std::fabs(dv.y);
        change_abs[2] += std::fabs(dv.z);
      });
      const Vec3 wg = shares[i].gradient;
      const double wall_g[3] = {wg.x, wg.y, wg.z};
      if (walls) {
        rate_abs += std::fabs(sph::wall_density_rate(dfsph_walls, i, vi));
        for (int a = 0; a < 3; ++a) change_abs[a] += std::fabs(wall_g[a] * k[i]);
      }
      const uint32_t nb = scalar.neighbor_count;
      pairs += nb;
      const sph::SimdPasses& generic = *targets.front();
      const sph::DfsphDensitySample simd = generic.dfsph_density_and_factor(f, view, columns, shares[i], i);
      const float rate = generic.dfsph_density_rate(f, view, columns, dfsph_walls, i);
      const Vec3 change = generic.dfsph_velocity_change(f, view, columns, k.data(), dfsph_walls, i, dt);
      bool ok = simd.neighbor_count == nb;
      ok = within_rounding(simd.density, scalar.density, scalar.density, nb, "DFSPH density", i) && ok;
      // The factor, through D (module comment above).
      const double e = 4.0 * (nb + 1) * kUnitRoundoff;
      double d_exact = squares, d_error = e * squares;
      for (int a = 0; a < 3; ++a) {
        const double g = g_sum[a] + wall_g[a];
        const double e_c = e * (g_abs[a] + std::fabs(wall_g[a]));
        d_exact += g * g;
        d_error += (2.0 * std::fabs(g) + e_c) * e_c;
      }
      d_error += 8.0 * kUnitRoundoff * d_exact;
      if (scalar.factor == 0.0f || simd.factor == 0.0f) {
        ok = ok && scalar.factor == simd.factor;  // no particle here sits at the floor
      } else {
        const double bound = scalar.factor * (d_error / (d_exact - d_error) + 2.0 * kUnitRoundoff);
        if (std::fabs(simd.factor - scalar.factor) > bound) {
          std::printf("  factor of particle %u: SIMD %.9g, scalar %.9g, bound %.3g\n", i, simd.factor,
                      scalar.factor, bound);
          ok = false;
        }
      }
      ok = within_rounding(rate, rate_scalar, rate_abs, nb + 1, "rate", i) && ok;
      ok = within_rounding(change.x, change_scalar.x, change_abs[0] * dt, nb + 1, "dv.x", i) && ok;
      ok = within_rounding(change.y, change_scalar.y, change_abs[1] * dt, nb + 1, "dv.y", i) && ok;
      ok = within_rounding(change.z, change_scalar.z, change_abs[2] * dt, nb + 1, "dv.z", i) && ok;
      // The corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT): the same sums and B_i's, then L_i = B_i^-1
      // (within the fade, |L| <= 1 / 0.94 per row in the bulk, a few where B is anisotropic) applied to
      // a difference of sums: bounded by 4 (n + 1) u of the terms' magnitudes, times 16 for the inverse's
      // rounding and norm.
      const Vec3 corrected_scalar =
          sph::pressure_velocity_change<true>(f, view, s.positions.data(), k.data(), dfsph_walls, i, dt);
      const Vec3 corrected =
          generic.dfsph_velocity_change_corrected(f, view, columns, k.data(), dfsph_walls, i, dt);
      {
        const double scale = 16.0 * dt * (change_abs[0] + change_abs[1] + change_abs[2]);
        ok = within_rounding(corrected.x, corrected_scalar.x, scale, nb + 1, "corrected dv.x", i) && ok;
        ok = within_rounding(corrected.y, corrected_scalar.y, scale, nb + 1, "corrected dv.y", i) && ok;
        ok = within_rounding(corrected.z, corrected_scalar.z, scale, nb + 1, "corrected dv.z", i) && ok;
      }
      for (const sph::SimdPasses* t : targets) {
        const bool same =
            same_bits(t->dfsph_velocity_change_corrected(f, view, columns, k.data(), dfsph_walls, i, dt),
                      corrected) &&
            same_bits(t->dfsph_density_and_factor(f, view, columns, shares[i], i), simd) &&
            same_bits(t->dfsph_density_rate(f, view, columns, dfsph_walls, i), rate) &&
            same_bits(t->dfsph_velocity_change(f, view, columns, k.data(), dfsph_walls, i, dt), change);
        if (!same && failures < 5) std::printf("  %s differs from generic at particle %u\n", t->name, i);
        ok = ok && same;
      }
      if (!ok) ++failures;
    }
    std::printf("DFSPH%s, cloud %zu: %u particles, %.1f neighbours each, %zu targets, %zu mismatches\n",
                walls ? " with walls" : "", c, s.n, static_cast<double>(pairs) / s.n, targets.size(),
                failures);
    assert_true(pairs > 20u * s.n);
    assert_int_equal(failures, 0);
  }
}

// The corrected gradient's point (physics/dfsph_gradient_correction.h): for a linear k_j = k0 + a . x_j
// the velocity change of a particle with a full neighbourhood (the fade's weight 1) is
// -dt (rho0 a + 2 beta k_i L_i Z_i) on any packing, L_i = B_i^-1 and Z_i = sum_j m grad W_ij computed
// here in double. On the random cloud the uncorrected update misses rho0 a by 10-30 % (B is not I)
// plus 2 k_i Z_i, so this fails without the correction.
void test_dfsph_corrected_gradient_is_first_order(void**) {
  Scene s(uniform_cloud(3000, Vec3{0.0f, 0.0f, 0.0f},
                        0.5f * std::cbrt(3000.0f * 4.18879f * kH * kH * kH / 40.0f), 11),
          50);
  const sph::FluidConstants f = s.fluid(sph::MethodSelection{});
  const sph::KernelCoefficients mk = sph::mass_gradient_kernel(f);
  const sph::GridView view = s.view();
  const float dt = 1e-3f, k0 = 5e-4f;
  const double a[3] = {1e-3, -2e-3, 3e-3};  // 1/m: k varies by about a fifth of k0 across h
  const double beta = sph::DfsphGradientCorrection::kKeptZeroth, rho0 = f.rest_density;
  std::vector<float> k(s.n + sph::kLanePadding, 0.0f);
  for (uint32_t i = 0; i < s.n; ++i)
    k[i] =
        k0 + static_cast<float>(a[0] * s.positions[i].x + a[1] * s.positions[i].y + a[2] * s.positions[i].z);
  const sph::DfsphWalls no_walls{nullptr};
  uint32_t checked = 0, failures = 0;
  double worst_uncorrected = 0.0;
  for (uint32_t i = 0; i < s.n; ++i) {
    const Vec3 xi = sph::xyz(s.positions[i]);
    double b[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, z[3] = {0, 0, 0}, g_abs = 0.0;
    sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
      const Vec3 d = xi - sph::xyz(s.positions[j]);
      const float r2 = sph::length_squared(d);
      if (r2 >= f.kernel.h2 || j == i) return;
      const Vec3 g = sph::spiky_gradient(mk, d, std::sqrt(r2));
      const double gv[3] = {g.x, g.y, g.z}, dv[3] = {d.x, d.y, d.z};
      for (int r = 0; r < 3; ++r) {
        z[r] += gv[r];
        g_abs += std::fabs(gv[r]);
        for (int c = 0; c < 3; ++c) b[r][c] -= gv[r] * dv[c] / rho0;
      }
    });
    if ((b[0][0] + b[1][1] + b[2][2]) / 3.0 < sph::DfsphGradientCorrection::kFull) continue;
    const double det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                       b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                       b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    const double l[3][3] = {
        {(b[1][1] * b[2][2] - b[1][2] * b[2][1]) / det, (b[0][2] * b[2][1] - b[0][1] * b[2][2]) / det,
         (b[0][1] * b[1][2] - b[0][2] * b[1][1]) / det},
        {(b[1][2] * b[2][0] - b[1][0] * b[2][2]) / det, (b[0][0] * b[2][2] - b[0][2] * b[2][0]) / det,
         (b[0][2] * b[1][0] - b[0][0] * b[1][2]) / det},
        {(b[1][0] * b[2][1] - b[1][1] * b[2][0]) / det, (b[0][1] * b[2][0] - b[0][0] * b[2][1]) / det,
         (b[0][0] * b[1][1] - b[0][1] * b[1][0]) / det}};
    const Vec3 got =
        sph::pressure_velocity_change<true>(f, view, s.positions.data(), k.data(), no_walls, i, dt);
    const Vec3 plain =
        sph::pressure_velocity_change<false>(f, view, s.positions.data(), k.data(), no_walls, i, dt);
    const double got_v[3] = {got.x, got.y, got.z}, plain_v[3] = {plain.x, plain.y, plain.z};
    double l_norm = 0.0;
    for (int r = 0; r < 3; ++r)
      l_norm = std::max(l_norm, std::fabs(l[r][0]) + std::fabs(l[r][1]) + std::fabs(l[r][2]));
    // Float sums of about 40 terms of size m |grad W| 2 k0 (the difference form cancels them down to
    // rho0 |a| h), then L: 16 (n + 1) u of that, n about 40.
    const double bound = 16.0 * 41.0 * kUnitRoundoff * dt * l_norm * 2.0 * (k0 + 1e-4) * g_abs;
    bool ok = true;
    for (int r = 0; r < 3; ++r) {
      const double expected =
          -dt * (rho0 * a[r] + 2.0 * beta * k[i] * (l[r][0] * z[0] + l[r][1] * z[1] + l[r][2] * z[2]));
      if (std::fabs(got_v[r] - expected) > bound) {
        if (failures < 5)
          std::printf("  particle %u, axis %d: corrected %.9g, expected %.9g, bound %.3g\n", i, r, got_v[r],
                      expected, bound);
        ok = false;
      }
      worst_uncorrected =
          std::max(worst_uncorrected, std::fabs(plain_v[r] + dt * rho0 * a[r]) / (dt * rho0 * 3e-3));
    }
    ++checked;
    if (!ok) ++failures;
  }
  std::printf(
      "corrected gradient, linear k: %u particles with a full correction, %u off; the uncorrected "
      "update misses rho0 a by up to %.0f times rho0 |a|_max (mostly 2 k_i Z_i)\n",
      checked, failures, worst_uncorrected);
  assert_true(checked > 300u);
  assert_int_equal(failures, 0);
  assert_true(worst_uncorrected > 0.05);
}

// The walls' share under the corrected gradient (dfsph_gradient_correction.h, corrected_wall_share):
// where the fade's weight is 1 the walls' term k_i grad rho_b keeps the share beta the fluid's
// zeroth-order term keeps, and the plain update keeps it whole. The same cloud with a wall record
// grad rho_b = (3, -2, 1) rho0 / h at every particle: the difference the walls make to each update
// is -dt beta k_i grad rho_b (corrected) and -dt k_i grad rho_b (plain), within the rounding of one
// addition and one product on sums of that size. Before session 26 the corrected update kept the
// walls' term whole, which pushed particles near a wall off it (docs/physics.md).
void test_dfsph_corrected_gradient_wall_share(void**) {
  Scene s(uniform_cloud(3000, Vec3{0.0f, 0.0f, 0.0f},
                        0.5f * std::cbrt(3000.0f * 4.18879f * kH * kH * kH / 40.0f), 11),
          50);
  const sph::FluidConstants f = s.fluid(sph::MethodSelection{});
  const sph::GridView view = s.view();
  const float dt = 1e-3f, k0 = 5e-4f;
  const double beta = sph::DfsphGradientCorrection::kKeptZeroth;
  const float scale = f.rest_density / f.kernel.h;
  const Vec3 wall{3.0f * scale, -2.0f * scale, 1.0f * scale};
  std::vector<float> k(s.n + sph::kLanePadding, k0);
  std::vector<sph::Float4> records(s.n, sph::Float4{wall.x, wall.y, wall.z, 0.0f});
  const sph::DfsphWalls no_walls{nullptr}, walls{records.data()};
  uint32_t full = 0, failures = 0;
  for (uint32_t i = 0; i < s.n; ++i) {
    const Vec3 corrected =
        sph::pressure_velocity_change<true>(f, view, s.positions.data(), k.data(), no_walls, i, dt);
    const Vec3 corrected_walls =
        sph::pressure_velocity_change<true>(f, view, s.positions.data(), k.data(), walls, i, dt);
    const Vec3 plain =
        sph::pressure_velocity_change<false>(f, view, s.positions.data(), k.data(), no_walls, i, dt);
    const Vec3 plain_walls =
        sph::pressure_velocity_change<false>(f, view, s.positions.data(), k.data(), walls, i, dt);
    // The fade's weight from the particle's own moment, as the update computes it.
    sph::GradientMomentOf<float> m = sph::zero_gradient_moment(0.0f);
    const sph::KernelCoefficients mk = sph::mass_gradient_kernel(f);
    const Vec3 xi = sph::xyz(s.positions[i]);
    sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
      const Vec3 d = xi - sph::xyz(s.positions[j]);
      const float r2 = sph::length_squared(d);
      if (r2 < f.kernel.h2 && j != i)
        sph::add_gradient_moment(m, sph::spiky_gradient(mk, d, std::sqrt(r2)), d);
    });
    const float weight = sph::corrected_pressure_sum(Vec3{0.0f, 0.0f, 0.0f}, m, k0, f.rest_density).weight;
    const double share = 1.0 - weight * (1.0 - beta);
    if (weight >= 1.0f) ++full;
    const double cw[3] = {corrected_walls.x - corrected.x, corrected_walls.y - corrected.y,
                          corrected_walls.z - corrected.z};
    const double pw[3] = {plain_walls.x - plain.x, plain_walls.y - plain.y, plain_walls.z - plain.z};
    const double wv[3] = {wall.x, wall.y, wall.z};
    const double c_size[3] = {std::fabs(corrected.x), std::fabs(corrected.y), std::fabs(corrected.z)};
    const double p_size[3] = {std::fabs(plain.x), std::fabs(plain.y), std::fabs(plain.z)};
    bool ok = true;
    for (int r = 0; r < 3; ++r) {
      const double want_c = -dt * share * k0 * wv[r], want_p = -dt * k0 * wv[r];
      // One addition, one product by -dt, and the share's and k_i's products: 8 u of the larger term.
      ok = ok && std::fabs(cw[r] - want_c) <= 8.0 * kUnitRoundoff * (c_size[r] + std::fabs(want_c) + 1e-30);
      ok = ok && std::fabs(pw[r] - want_p) <= 8.0 * kUnitRoundoff * (p_size[r] + std::fabs(want_p) + 1e-30);
      if (!ok && failures < 5)
        std::printf(
            "  particle %u axis %d: walls' part corrected %.9g (want %.9g, weight %.3f), plain %.9g (want "
            "%.9g)\n",
            i, r, cw[r], want_c, static_cast<double>(weight), pw[r], want_p);
    }
    if (!ok) ++failures;
  }
  std::printf("corrected gradient's walls' share: %u particles with a full correction, %u of %u off\n", full,
              failures, s.n);
  assert_true(full > 300u);
  assert_int_equal(failures, 0);
}

void test_dfsph_passes(void**) { check_dfsph(false); }
void test_dfsph_passes_walls(void**) { check_dfsph(true); }

// The best target is one this processor runs, and the x86 targets are built on x86-64.
void test_dispatch(void**) {
  const sph::SimdPasses& best = sph::best_simd_passes();
  std::printf("best SIMD target here: %s\n", best.name);
  assert_true(sph::simd_target_runs(best.target));
  assert_true(sph::simd_target_runs(sph::SimdTarget::Generic));
#if defined(__x86_64__)
  assert_non_null(sph::simd_passes_built(sph::SimdTarget::Avx2));
  assert_non_null(sph::simd_passes_built(sph::SimdTarget::Avx512));
#endif
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_dispatch),
      cmocka_unit_test(test_density_passes),
      cmocka_unit_test(test_forces_mueller),
      cmocka_unit_test(test_forces_clavet),
      cmocka_unit_test(test_forces_surface_tension),
      cmocka_unit_test(test_dfsph_passes),
      cmocka_unit_test(test_dfsph_passes_walls),
      cmocka_unit_test(test_dfsph_corrected_gradient_is_first_order),
      cmocka_unit_test(test_dfsph_corrected_gradient_wall_share),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
