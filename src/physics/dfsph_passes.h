// SPDX-License-Identifier: MIT
// DFSPH's per-particle passes (the method is dfsph.h; the order of a substep is each backend's).
// Three gathers over the neighbours, each written once for both backends:
//   gather_density_and_factor  rho_i and the factor alpha_i / rho_i = 1 / D_i,
//                              D_i = |sum_j m grad W_ij|^2 + sum_j |m grad W_ij|^2
//   density_rate               D rho_i / Dt = sum_j m (v_i - v_j) . grad W_ij
//   pressure_velocity_change   -dt sum_j m (k_i + k_j) grad W_ij,  k = kappa / rho = p / rho^2
//                              (<true>: with the corrected gradient, dfsph_gradient_correction.h)
// and the per-particle step between them (divergence_residual, density_residual) that turns a
// rate into the particle's pressure k_i and its share of the solve's mean error. The walls enter
// each gather through one call (dfsph_boundary.h).
//
// With k_i = e_i alpha_i / (dt rho_i) (divergence, e = D rho / Dt) or e_i alpha_i / (dt^2 rho_i)
// (density, e = rho* - rho0), a particle's own k_i alone, applied by the velocity update to it and
// its neighbours, changes its rate by -e_i / dt (density: its predicted density by -e_i): the
// Jacobi step of Bender & Koschier 2017, eq. 9-11. alpha_i / rho_i = 1 / D_i, so the passes need
// no density.
//
// The gradient is the world's grad W_spiky (lattice-scaled, as the density and the weakly
// compressible pressure force use it) with the particle mass folded into its coefficient, so
// that m grad W is one product per pair and stays within float range at any spacing the world
// accepts (grad W alone reaches 1e24 at micrometre spacings; its square would overflow).
#pragma once

#include <stdint.h>

#include "collider_response.h"
#include "dfsph.h"
#include "dfsph_boundary.h"
#include "dfsph_gradient_correction.h"
#include "float4_types.h"
#include "fluid_base.h"
#include "kernels.h"
#include "neighbor_walk.h"

namespace sph {

// grad W_spiky times the particle mass: m grad W = spiky_gradient(mass_gradient(f), d, r).
SPH_HD KernelCoefficients mass_gradient_kernel(const FluidBase& f) {
  KernelCoefficients k = f.kernel;
  k.spiky_grad *= f.particle_mass;
  return k;
}

struct DfsphDensitySample {
  float density;            // rho_i = m (w0 + sum_{j != i} W_ij) + the walls' share
  uint32_t neighbor_count;  // particles with r < h, self excluded
  float factor;             // alpha_i / rho_i = 1 / D_i, or 0 where D_i is too small
};

// The pair terms of the three gathers, for a neighbour j of i (r2 < h^2, j != i) at
// d = x_i - x_j, r = |d|. T is float or a pack of lanes (lane_math.h): the scalar gathers below
// (both backends) and the CPU backend's SIMD passes (src/cpu/cpu_simd_gathers.h) add the same
// terms, so only the order of the sums can differ between them.
//
// The density and factor pass: W_ij, m grad W_ij and |m grad W_ij|^2 (mk: mass_gradient_kernel).
template <class T>
struct DfsphFactorTermsOf {
  T kernel;
  Vec3Of<T> gradient;
  T square;
};
template <class T>
SPH_HD DfsphFactorTermsOf<T> dfsph_factor_pair_terms(const FluidBase& f, const KernelCoefficients& mk,
                                                     Vec3Of<T> d, T r2) {
  const T r = square_root(r2);
  const Vec3Of<T> g = spiky_gradient(mk, d, r);
  return DfsphFactorTermsOf<T>{spiky_value(f.kernel, r), g, length_squared(g)};
}

// The density rate: m (v_i - v_j) . grad W_ij (v_ij = v_i - v_j).
template <class T>
SPH_HD T density_rate_pair_term(const KernelCoefficients& mk, Vec3Of<T> d, T r2, Vec3Of<T> v_ij) {
  return dot(v_ij, spiky_gradient(mk, d, square_root(r2)));
}

// The velocity update: m (k_i + k_j) grad W_ij (k_ij = k_i + k_j).
template <class T>
SPH_HD Vec3Of<T> pressure_velocity_pair_term(const KernelCoefficients& mk, Vec3Of<T> d, T r2, T k_ij) {
  return spiky_gradient(mk, d, square_root(r2)) * k_ij;
}

// What each gather makes of its sums and the walls' share (one text for every path).
// kernel_sum = sum_j W_ij, gradient = sum_j m grad W_ij, squares = sum_j |m grad W_ij|^2.
SPH_HD DfsphDensitySample dfsph_density_and_factor(const FluidBase& f, float kernel_sum, uint32_t neighbors,
                                                   Vec3 gradient, float squares, const BoundaryShare& wall) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  // Boundary place 1: the walls' density and their gradient in alpha (dfsph_boundary.h).
  const float density = f.particle_mass * (f.density_self_weight + kernel_sum) + wall.density;
  gradient += wall.gradient;
  const float denominator = length_squared(gradient) + squares;
  // One pair's largest term, (m |grad W(0)|)^2: the scale below which alpha would blow up.
  const float pair_max = -mk.spiky_grad * f.kernel.h2;
  const float smallest = Dfsph::kFactorFloor * pair_max * pair_max;
  return DfsphDensitySample{density, neighbors, denominator > smallest ? 1.0f / denominator : 0.0f};
}
// sum = sum_j m (v_i - v_j) . grad W_ij.
SPH_HD float dfsph_density_rate(float sum, const DfsphWalls& walls, uint32_t i, Vec3 vi) {
  return sum + wall_density_rate(walls, i, vi);  // boundary place 2: the walls' relative motion
}
// sum = sum_j m (k_i + k_j) grad W_ij.
SPH_HD Vec3 dfsph_velocity_change(Vec3 sum, const DfsphWalls& walls, uint32_t i, float ki, float dt) {
  sum += wall_pressure_gradient(walls, i) * ki;  // boundary place 3: the walls' share, k_i alone
  return sum * (-dt);
}

// The bound of a candidate mask's test (neighbor_walk.h), r^2 < h^2 widened by 2^-12 of itself:
// far more than the few ulps by which two compilations of r^2 can differ (FMA contraction), so a
// mask never drops a candidate that a pass's own r^2 < h^2 keeps. The passes still test what
// they visit: the masked walk gives them the same terms in the same order, whatever the mask's
// few extra candidates at r just above h.
SPH_HD float neighbor_mask_bound(float h2) { return h2 + h2 * 2.44140625e-4f; }

// The density pass's walk without a mask to record (NeighborMaskWriter's interface).
struct NoNeighborMask {
  SPH_HD void add(bool, uint32_t) {}
  SPH_HD void finish() const {}
};

// The density pass's walk without a second sum over its pairs (gather_density_and_factor's pair).
struct NoPairSum {
  SPH_HD void operator()(uint32_t, Vec3, float) const {}
};

// The density of density.h (the same sum in the same order) and the factor, in one walk.
// wall: the walls' share at x_i (boundary_share; no_boundary_share() without the feature).
// mask: NeighborMaskWriter to record particle i's candidate mask (and, with lists, its neighbour
// list) for the solves' passes. pair(j, d, r2): called for each neighbour (r < h, j != i) in the
// walk's order, so that another sum over the same pairs rides in this walk (the CUDA pass's
// divergence warm start, cuda/dfsph_density.cu).
template <class Mask = NoNeighborMask, class Pair = NoPairSum>
SPH_HD DfsphDensitySample gather_density_and_factor(const FluidBase& f, const GridView& grid,
                                                    const Float4* positions, const BoundaryShare& wall,
                                                    uint32_t i, Mask mask = Mask{}, Pair&& pair = Pair{}) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi = xyz(positions[i]);
  const float bound = neighbor_mask_bound(f.kernel.h2);
  float sum = 0.0f;
  uint32_t neighbors = 0;
  Vec3 gradient{0.0f, 0.0f, 0.0f};  // sum_j m grad W_ij
  float squares = 0.0f;             // sum_j |m grad W_ij|^2
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    mask.add(r2 < bound && j != i, j);
    if (r2 < f.kernel.h2 && j != i) {
      const DfsphFactorTermsOf<float> t = dfsph_factor_pair_terms(f, mk, d, r2);
      sum += t.kernel;
      ++neighbors;
      gradient += t.gradient;
      squares += t.square;
      pair(j, d, r2);
    }
  });
  mask.finish();
  return dfsph_density_and_factor(f, sum, neighbors, gradient, squares, wall);
}

// D rho_i / Dt = sum_j m (v_i - v_j) . grad W_ij over the velocities `velocities` (xyz).
// walk: the candidates it visits (neighbor_walk.h: AllCandidates, or on CUDA ListedCandidates, which
// walks the particle's neighbour list or its mask).
template <class Walk = AllCandidates>
SPH_HD float density_rate(const FluidBase& f, const GridView& grid, const Float4* positions,
                          const Float4* velocities, const DfsphWalls& walls, uint32_t i, Walk walk = Walk{}) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi = xyz(positions[i]);
  const Vec3 vi = xyz(velocities[i]);
  float rate = 0.0f;
  walk(grid, xi, i, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 < f.kernel.h2 && j != i) rate += density_rate_pair_term(mk, d, r2, vi - xyz(velocities[j]));
  });
  return dfsph_density_rate(rate, walls, i, vi);
}

// The corrected gradient's ending (SPH_DFSPH_CORRECTED_GRADIENT, dfsph_gradient_correction.h): sum as
// dfsph_velocity_change's, m the moment (B_i and the zeroth-order sum) gathered in the same walk.
SPH_HD Vec3 dfsph_corrected_velocity_change(const FluidBase& f, Vec3 sum, const GradientMomentOf<float>& m,
                                            const DfsphWalls& walls, uint32_t i, float ki, float dt) {
  const CorrectedPressureSum c = corrected_pressure_sum(sum, m, ki, f.rest_density);
  return dfsph_velocity_change(c.sum, walls, i, ki * corrected_wall_share(c.weight), dt);
}

// The velocity change of particle i from the pressures k (k_j = p_j / rho_j^2 of this
// iteration): -dt sum_j m (k_i + k_j) grad W_ij, which pushes compressed neighbours apart.
// kCorrected: with the corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT), whose moment is gathered
// in the same walk from the gradient before its product; without it the walk gathers the sum alone.
// The two branches are the SIMD twin's (cpu_simd_gathers.h), and each compiles to the code of the
// two functions this one replaced (CUDA's PTX compared). walk: as density_rate's.
template <bool kCorrected, class Walk = AllCandidates>
SPH_HD Vec3 pressure_velocity_change(const FluidBase& f, const GridView& grid, const Float4* positions,
                                     const float* k, const DfsphWalls& walls, uint32_t i, float dt,
                                     Walk walk = Walk{}) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi = xyz(positions[i]);
  const float ki = k[i];
  Vec3 sum{0.0f, 0.0f, 0.0f};
  GradientMomentIf<float, kCorrected> moment = gradient_moment_if<kCorrected>(0.0f);
  walk(grid, xi, i, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (!(r2 < f.kernel.h2 && j != i)) return;
    if constexpr (kCorrected) {
      const Vec3 g = spiky_gradient(mk, d, square_root(r2));
      sum += g * (ki + k[j]);
      add_gradient_moment(moment, g, d);
    } else {
      sum += pressure_velocity_pair_term(mk, d, r2, ki + k[j]);
    }
  });
  if constexpr (kCorrected)
    return dfsph_corrected_velocity_change(f, sum, moment, walls, i, ki, dt);
  else
    return dfsph_velocity_change(sum, walls, i, ki, dt);
}

// One particle's result of a residual pass.
struct DfsphResidual {
  float k;      // its pressure p / rho^2 for the next velocity update
  float error;  // its share of the solve's mean error: e_i / rho0
};

// The divergence solve: e = D rho / Dt, clamped at 0 (only compression is corrected), and 0 for
// a particle with fewer neighbours than the constants allow (a free surface, a splash).
// error in 1/s.
SPH_HD DfsphResidual divergence_residual(const Dfsph::Constants& c, float rate, uint32_t neighbors,
                                         float factor, float rest_density, float dt) {
  const float e = (neighbors >= c.min_divergence_neighbors && rate > 0.0f) ? rate : 0.0f;
  return DfsphResidual{e * factor / dt, e / rest_density};
}

// The density solve: e = max(rho* - rho0, 0), rho* = rho_i + dt D rho_i / Dt the density the
// velocities would give after the step. error dimensionless.
SPH_HD DfsphResidual density_residual(float rate, float density, float factor, float rest_density, float dt) {
  const float predicted = density + dt * rate;
  const float e = predicted > rest_density ? predicted - rest_density : 0.0f;
  return DfsphResidual{e * factor / (dt * dt), e / rest_density};
}

// The colliders' no-penetration inside the solves. The collision response after the step stops a
// particle at a wall whatever velocity the solves gave it; a solve that does not know this
// relieves the compression of a particle pressed against a wall by moving it into the wall,
// which the response then undoes, and the fluid at walls and corners ends up compressed by tens
// of percent (measured: a dam break's corner at 1.28 rho0, a quarter of its particles above
// 1.05 rho0, where the weakly compressible scheme stays below 1.03). So each particle within h
// of a collider carries its contact, (n, c): n the wall's normal (into the fluid) and c the
// smallest normal velocity it can have, c = v_wall . n - d / dt with d its distance from the
// wall (it can approach by d within the step), and every velocity the solves make is held to
// v . n >= c. The nearest collider wins where several are near. A boundary model that puts the
// walls into the density (dfsph_boundary.h) makes the solves see the approach as compression,
// and this becomes a safeguard.
// collider: the nearest collider's index (whose wall receives the clamp's impulses, collider_loads.h),
// or collider_count without a contact.
SPH_HD Float4 wall_contact(const ColliderView* colliders, uint32_t collider_count, const SubstepTime& t,
                           float kernel_radius, Vec3 x, uint32_t& collider) {
  Float4 contact{0.0f, 0.0f, 0.0f, 0.0f};  // no contact: n = 0 holds nothing
  float nearest = kernel_radius;
  collider = collider_count;
  for (uint32_t c = 0; c < collider_count; ++c) {
    const ColliderSample s = sample_collider(colliders[c], x, t.s0, t.tau0);
    if (!(s.distance < nearest)) continue;
    nearest = s.distance;
    collider = c;
    const Vec3 n = collider_normal(colliders[c], s);
    const float d = s.distance > 0.0f ? s.distance : 0.0f;
    contact = make_float4_record(n, dot(collider_velocity(colliders[c], s, x), n) - d / t.dt);
  }
  return contact;
}
SPH_HD Float4 wall_contact(const ColliderView* colliders, uint32_t collider_count, const SubstepTime& t,
                           float kernel_radius, Vec3 x) {
  uint32_t collider = 0;
  return wall_contact(colliders, collider_count, t, kernel_radius, x, collider);
}

// v held to its contact: v . n >= c.
SPH_HD Vec3 respect_contact(const Float4& contact, Vec3 v) {
  const Vec3 n = xyz(contact);
  const float vn = dot(v, n);
  return vn < contact.w ? v + n * (contact.w - vn) : v;
}

// The pressure a substep applied (the attribute SPH_ATTRIBUTE_PRESSURE): both solves' p / rho^2
// act in the same substep with the same dt, so p = (k + k_v) rho^2 (k_v: the divergence solve's
// p / rho^2, its carried impulse over dt).
SPH_HD float dfsph_pressure(float k, float k_divergence, float density) {
  return (k + k_divergence) * density * density;
}

}  // namespace sph
