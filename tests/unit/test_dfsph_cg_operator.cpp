// SPDX-License-Identifier: MIT
// The operator of DFSPH's density solve by conjugate gradients (physics/dfsph_cg.h), built as a
// dense matrix from the CPU backend's own passes, with and without the walls in the density.
//
// A p is what cpu_dfsph_cg.cpp applies each iteration: the velocity change dv = -dt G p of the
// pressures p (the SIMD velocity update, the walls' share with p_i alone), then the change of
// the predicted density that dv alone makes (the SIMD rate pass, the walls' share dv_i . grad
// rho_b), A p = -change / dt^2. With D = G^T (dfsph_cg.h) A = G^T G: symmetric, positive
// semidefinite, its diagonal the DFSPH factor's denominator 1 / (alpha_i / rho_i). Built column by
// column from unit vectors on a small tank (an FCC block, the walls spacing / 2 beyond its outer
// layers on the floor and four sides as flat density maps, the top free):
//   1. ||A - A^T|| / ||A|| within float rounding (1e-5: each entry a sum of about 40 products of
//      float terms, u = 6e-8 each, and the cancellation of a smooth column's sums);
//   2. A_ii = 1 / factor_i within the same rounding (the preconditioner is A's diagonal);
//   3. the eigenvalues of (A + A^T) / 2, by Jacobi rotations in double: none below -1e-5 of the
//      largest (positive semidefinite within rounding), and the contacts' projection (a particle
//      moving along its wall only) keeps all three.
// What the conjugate gradients rely on, and the measurement docs/validation.md quotes ("DFSPH by
// conjugate gradients, the walls in the density").
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/config.h"
#include "cpu/cpu_neighbor_columns.h"
#include "cpu/cpu_neighbor_grid.h"
#include "cpu/cpu_simd_passes.h"
#include "physics/boundary_integrals.h"
#include "physics/dfsph_cg.h"
#include "physics/dfsph_passes.h"

namespace {

using sph::Float4;
using sph::Vec3;

constexpr float kSpacing = 0.02f;
constexpr float kH = 1.8f * kSpacing;
constexpr float kRho0 = 1000.0f;
// The boundary calibration at h = 1.8 spacings (boundary_density.h): K = 12.0 rho0, delta 0.49
// spacings.
constexpr float kWallScale = 12.0f * kRho0;
constexpr float kWallOffset = 0.49f * kSpacing;
constexpr float kDt = 2e-3f;

struct Tank {
  sph::WorldConfig config;
  sph::CpuNeighborGrid grid{kH, UINT32_MAX};
  sph::CpuNeighborColumns columns{true, true};
  std::vector<Float4> positions;
  std::vector<Float4> records;  // the walls' (grad rho_b, flux), or none
  std::vector<Float4> contacts;
  std::vector<float> factor;
  uint32_t n = 0;
  sph::FluidConstants fluid{};
};

// An FCC block of nx x ny x nz lattice steps (step = spacing / sqrt 2), the walls (x, z on both
// sides, the floor) spacing / 2 beyond its outer layers.
Tank make_tank(uint32_t nx, uint32_t ny, uint32_t nz, bool walls) {
  Tank t;
  t.config.kernel_radius = kH;
  t.config.rest_density = kRho0;
  t.config.particle_spacing = kSpacing;
  t.config.particle_mass = kRho0 * kSpacing * kSpacing * kSpacing / std::sqrt(2.0f);
  t.config.density_self_weight = 60000.0f;
  sph::RuntimeParams params;
  t.fluid = sph::make_fluid_constants(t.config, params);
  t.fluid.dt = kDt;
  const float step = kSpacing / std::sqrt(2.0f);
  std::vector<Float4> raw;
  for (uint32_t k = 0; k < nz; ++k)
    for (uint32_t j = 0; j < ny; ++j)
      for (uint32_t i = 0; i < nx; ++i)
        if ((i + j + k) % 2 == 0)
          raw.push_back(sph::make_float4_record(Vec3{i * step, j * step, k * step}, 0.0f));
  t.n = static_cast<uint32_t>(raw.size());
  t.grid.build(raw.data(), t.n, 1);
  t.positions.resize(t.n);
  for (uint32_t i = 0; i < t.n; ++i) t.positions[i] = raw[t.grid.order()[i]];
  // The walls' planes: (point on the plane, normal into the fluid).
  const float g = 0.5f * kSpacing;
  const Vec3 lo{-g, -g, -g}, hi{(nx - 1) * step + g, 0.0f, (nz - 1) * step + g};
  const Vec3 normals[5] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}};
  const Vec3 points[5] = {lo, hi, lo, lo, hi};
  t.records.assign(t.n, Float4{0.0f, 0.0f, 0.0f, 0.0f});
  t.contacts.assign(t.n, Float4{0.0f, 0.0f, 0.0f, 0.0f});
  std::vector<sph::BoundaryShare> shares(t.n, sph::no_boundary_share());
  for (uint32_t i = 0; i < t.n; ++i) {
    const Vec3 x = sph::xyz(t.positions[i]);
    float nearest = kH;
    for (int w = 0; w < 5; ++w) {
      const float d = sph::dot(x - points[w], normals[w]);  // distance from the wall into the fluid
      if (walls) {
        // Phi = the share of the kernel beyond the plane moved delta into the solid.
        const float phi = sph::spiky_half_space(d + kWallOffset, kH);
        const float slope = sph::spiky_half_space_slope(d + kWallOffset, kH);  // dPhi / dd
        shares[i].density += kWallScale * phi;
        shares[i].gradient += normals[w] * (kWallScale * slope);  // into the solid (slope < 0)
      }
      if (d < nearest) {  // the contact: the nearest wall's normal, at rest
        nearest = d;
        t.contacts[i] = sph::make_float4_record(normals[w], -d / kDt);
      }
    }
    t.records[i] = sph::pack_boundary(shares[i]);
  }
  t.columns.resize(t.n);
  std::vector<Float4> still(t.n, Float4{0.0f, 0.0f, 0.0f, 1.0f / kRho0});
  t.columns.copy_state(t.positions.data(), still.data(), 0, t.n);
  const sph::SimdPasses& simd = sph::best_simd_passes();
  t.factor.resize(t.n);
  for (uint32_t i = 0; i < t.n; ++i)
    t.factor[i] =
        simd.dfsph_density_and_factor(t.fluid, t.grid.view(), t.columns.view(), shares[i], i).factor;
  return t;
}

// A as cpu_dfsph_cg.cpp applies it, column by column; project: the contacts' projection for every
// particle with a contact (all bind, as at rest against the wall).
std::vector<double> build_operator(Tank& t, bool walls, bool project) {
  const uint32_t n = t.n;
  const sph::SimdPasses& simd = sph::best_simd_passes();
  const sph::DfsphWalls dw{walls ? t.records.data() : nullptr};
  std::vector<float> p(n + sph::kLanePadding, 0.0f);
  std::vector<double> a(static_cast<size_t>(n) * n);
  const float unit = 1e-4f;  // a k = p / rho^2 of a few cm of water
  for (uint32_t k = 0; k < n; ++k) {
    std::fill(p.begin(), p.end(), 0.0f);
    p[k] = unit;
    const sph::NeighborColumns view = t.columns.view();
    std::vector<Vec3> dv(n);
    for (uint32_t i = 0; i < n; ++i) {
      dv[i] = simd.dfsph_velocity_change(t.fluid, t.grid.view(), view, p.data(), dw, i, kDt);
      if (project) dv[i] = sph::dfsph_contact_project(t.contacts[i], dv[i]);
    }
    for (uint32_t i = 0; i < n; ++i) t.columns.set_velocity(i, dv[i]);
    for (uint32_t i = 0; i < n; ++i) {
      const float change = sph::dfsph_cg_change(
          simd.dfsph_density_rate(t.fluid, t.grid.view(), t.columns.view(), dw, i), dw, i, kDt);
      a[static_cast<size_t>(i) * n + k] =
          -static_cast<double>(change) / (static_cast<double>(kDt) * kDt * unit);
    }
  }
  for (uint32_t i = 0; i < n; ++i) t.columns.set_velocity(i, Vec3{0.0f, 0.0f, 0.0f});
  return a;
}

// The eigenvalues of a symmetric matrix (cyclic Jacobi rotations; n of a few hundred).
std::vector<double> eigenvalues(std::vector<double> s, uint32_t n) {
  for (int sweep = 0; sweep < 60; ++sweep) {
    double off = 0.0, total = 0.0;
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t j = 0; j < n; ++j) {
        const double v = s[static_cast<size_t>(i) * n + j] * s[static_cast<size_t>(i) * n + j];
        total += v;
        if (i != j) off += v;
      }
    if (off <= 1e-26 * total) break;
    for (uint32_t p = 0; p < n; ++p)
      for (uint32_t q = p + 1; q < n; ++q) {
        const double apq = s[static_cast<size_t>(p) * n + q];
        if (std::fabs(apq) < 1e-300) continue;
        const double app = s[static_cast<size_t>(p) * n + p], aqq = s[static_cast<size_t>(q) * n + q];
        const double theta = 0.5 * (aqq - app) / apq;
        const double tt = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(tt * tt + 1.0), sn = tt * c;
        for (uint32_t k = 0; k < n; ++k) {  // columns p, q
          const double skp = s[static_cast<size_t>(k) * n + p], skq = s[static_cast<size_t>(k) * n + q];
          s[static_cast<size_t>(k) * n + p] = c * skp - sn * skq;
          s[static_cast<size_t>(k) * n + q] = sn * skp + c * skq;
        }
        for (uint32_t k = 0; k < n; ++k) {  // rows p, q
          const double spk = s[static_cast<size_t>(p) * n + k], sqk = s[static_cast<size_t>(q) * n + k];
          s[static_cast<size_t>(p) * n + k] = c * spk - sn * sqk;
          s[static_cast<size_t>(q) * n + k] = sn * spk + c * sqk;
        }
      }
  }
  std::vector<double> e(n);
  for (uint32_t i = 0; i < n; ++i) e[i] = s[static_cast<size_t>(i) * n + i];
  std::sort(e.begin(), e.end());
  return e;
}

void check_operator(bool walls, bool project) {
  Tank t = make_tank(8, 8, 8, walls);
  const uint32_t n = t.n;
  const std::vector<double> a = build_operator(t, walls, project);
  double norm = 0.0, skew = 0.0, worst_diagonal = 0.0;
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = 0; j < n; ++j) {
      const double v = a[static_cast<size_t>(i) * n + j], w = a[static_cast<size_t>(j) * n + i];
      norm += v * v;
      skew += (v - w) * (v - w);
    }
  const double asymmetry = std::sqrt(skew / norm);
  if (!project)
    for (uint32_t i = 0; i < n; ++i) {
      const double d = a[static_cast<size_t>(i) * n + i];
      worst_diagonal = std::max(worst_diagonal, std::fabs(d * t.factor[i] - 1.0));
    }
  std::vector<double> s(a.size());
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = 0; j < n; ++j)
      s[static_cast<size_t>(i) * n + j] =
          0.5 * (a[static_cast<size_t>(i) * n + j] + a[static_cast<size_t>(j) * n + i]);
  // The Jacobi-preconditioned operator's eigenvalues too (what the conjugate gradients' rate sees).
  std::vector<double> m(s);
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = 0; j < n; ++j)
      m[static_cast<size_t>(i) * n + j] *= std::sqrt(static_cast<double>(t.factor[i]) * t.factor[j]);
  const std::vector<double> e = eigenvalues(s, n);
  const std::vector<double> ep = eigenvalues(m, n);
  std::printf(
      "%s%s: %u particles; ||A - A^T|| / ||A|| = %.2e; worst |A_ii factor_i - 1| = %.2e; eigenvalues of "
      "(A + A^T)/2 %.4g .. %.4g (smallest / largest %.2e); preconditioned %.4g .. %.4g\n",
      walls ? "walls in the density" : "walls by contact only", project ? ", contacts projected" : "", n,
      asymmetry, worst_diagonal, e.front(), e.back(), e.front() / e.back(), ep.front(), ep.back());
  assert_true(asymmetry < 1e-5);
  if (!project) assert_true(worst_diagonal < 1e-5);
  assert_true(e.front() > -1e-5 * e.back());
}

void test_operator_without_walls(void**) { check_operator(false, false); }
void test_operator_walls(void**) { check_operator(true, false); }
void test_operator_walls_projected(void**) { check_operator(true, true); }

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_operator_without_walls),
      cmocka_unit_test(test_operator_walls),
      cmocka_unit_test(test_operator_walls_projected),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
