// SPDX-License-Identifier: MIT
// Normalised density (thesis eq. 31) over densities carried per particle.
//
// Near a free surface (and near a collider wall: there are no wall particles) the plain sum
// rho_i = sum_j m W_ij (eq. 9) misses the neighbours beyond it and reads low: about half of the
// interior's on the outermost layer of a resting body. Eq. 31, rho~_i = sum_j m W_ij /
// sum_j (m / rho_j) W_ij, divides by the kernel's discrete partition of unity; but with rho_j
// from the same plain pass it is only a Shepard filter (a W-weighted harmonic mean of the
// neighbours' densities) and cannot restore values the whole neighbourhood lacks (48 % -> 34 %
// on the outer layer). Nothing computed from the current positions alone can: a half-empty
// neighbourhood at a surface and a uniformly expanded fluid sum to the same.
//
// So every particle carries a factor g_i and its density is rho_i = g_i sum_j m W_ij:
//   - between filters g_i is constant, so rho_i changes in the same ratio as its kernel sum:
//     d ln rho_i / dt = d ln (sum_j m W_ij) / dt, the continuity equation with the divergence
//     taken from the density kernel and normalised by the kernel sum, integrated exactly along
//     the particle paths (no time-step error). In the bulk (g = 1) this is the plain
//     summation; at a surface it makes a uniformly compressed body read compressed to its last
//     layer (an offset added instead of a factor reads the surface layer too little
//     compressed, by its missing fraction, and measured worse: docs/physics.md);
//   - a particle enters the world with g_i = max(1, rho0 / sum_j m W_ij) at its first density
//     pass: fluid is assumed placed at (or above) rest density, so a missing neighbourhood is
//     read as free surface, while a block spawned compressed reads compressed;
//   - every density pass then applies eq. 31 to the carried densities as a Shepard filter (the
//     re-initialisation of Colagrossi & Landrini 2003): rho_i <- sum_j m W_ij /
//     sum_j (m / rho_j) W_ij, and g_i takes the ratio to the kernel sum. The filter keeps a
//     constant field exactly, even at a surface, so a resting body stays at rho0 to its last
//     layer and a uniformly compressed one stays compressed; it spreads a stale factor into
//     the neighbours when a particle moves from the surface into the bulk or back. It does
//     not keep a linear field at a surface or wall (it pulls the boundary value towards the
//     interior's), which bends a hydrostatic profile near them (docs/physics.md has the
//     numbers; a first-order, MLS, filter keeps linear fields but measured much worse in a
//     dynamic tank: it amplifies particle noise at boundaries).
// - where the kernel sum sees a full neighbourhood (sum_j m W_ij, walls' share included, at or
//   above rho0) g_i relaxes towards 1 over kFactorRelaxationTimes acoustic times h / c0:
//   g_i <- g_i + (1 - g_i) min(1, dt c0 / (N h)). There the summation reads the compression
//   itself, and a factor away from 1 is either noise that the filter or the diffusion is
//   smoothing (acoustic times, untouched) or a stale memory that they put in: both move density
//   between neighbours as if it were real, so a compression they smoothed away (a dam break's
//   impact on a wall, the walls' over-read along edges) stays hidden in g_i < 1 and the packed
//   fluid reads rest density without pressure (the dam break's wall pressure read 37-52 % low,
//   its particles at the wall 6 % denser in the kernel sum than in the carried density). Free
//   surfaces and rarefied fluid (sum below rho0) keep their factor.
// g_i is per-particle state: sorted, rolled back and checkpointed with the particles; a fresh
// particle's factor is NaN until its first density pass.
#pragma once

#include <stdint.h>

#include <limits>

#include "float4_types.h"
#include "fluid_base.h"
#include "neighbor_walk.h"
#include "param_table.h"
#include "particle_array_spec.h"

namespace sph {

struct NormalizedDensity {
  static constexpr const char* kName = "normalized_density";
  // g_i is carried state (NaN until the particle's first density pass); the plain kernel sum,
  // then the filtered density, is a per-pass side array.
  static constexpr float kFreshFactor = std::numeric_limits<float>::quiet_NaN();
  static constexpr ParticleArraySpec kArrays[] = {
      {kArrayDensityFactor, sizeof(float), ParticleArrayRole::Carried, 1, &kFreshFactor, nullptr},
      {kArrayNormalizedDensity, sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr}};
};

// The factor of a particle that has not had a density pass yet (set on the host, at append).
inline float fresh_density_factor() { return std::numeric_limits<float>::quiet_NaN(); }

SPH_HD bool is_fresh_density_factor(float factor) { return factor != factor; }

// rho_i = g_i * summed, resolving a fresh particle's factor first (written back). summed > 0:
// it includes the particle's own m W(0).
SPH_HD float carried_density(const FluidBase& f, float summed, float& factor) {
  if (is_fresh_density_factor(factor)) factor = summed < f.rest_density ? f.rest_density / summed : 1.0f;
  return summed * factor;
}

// The relaxation time of the carried factor, in acoustic times h / c0: long against the
// acoustic noise that the filter and the diffusion damp, short against a flow's time
// (docs/physics.md, "Normalised density", has the measured choice).
constexpr float kFactorRelaxationTimes = 20.0f;

// The share of the way to 1 a factor moves over dt: min(1, dt c0 / (N h)); 0 without a speed of
// sound.
SPH_HD float density_factor_relaxation(float dt, float sound_speed, float kernel_radius) {
  const float a = dt * sound_speed / (kFactorRelaxationTimes * kernel_radius);
  return a < 1.0f ? a : 1.0f;
}

// g_i relaxed by that share where the kernel sum (walls' share included) is at or above rho0.
SPH_HD float relaxed_density_factor(const FluidBase& f, float summed, float factor, float share) {
  return summed >= f.rest_density ? factor + (1.0f - factor) * share : factor;
}

// The Shepard filter's result for particle i (its filtered density and kernel sum): the factor
// that carries it, relaxed by share, and the density that factor reads.
struct FilteredDensity {
  float density;
  float factor;
};
SPH_HD FilteredDensity filtered_density(const FluidBase& f, float filtered, float summed, float share) {
  const float factor = relaxed_density_factor(f, summed, filtered / summed, share);
  return FilteredDensity{factor * summed, factor};
}

// Eq. 31's pair terms for a neighbour at squared distance r2 (< h^2, self included) with carried
// 1 / rho_j: W_poly6 to the mass sum, W_poly6 / rho_j to the volume sum. T is float or a pack of
// lanes (lane_math.h; the CPU backend's SIMD pass).
template <class T>
struct NormalizedDensityPair {
  T mass;
  T volume;
};
template <class T>
SPH_HD NormalizedDensityPair<T> normalized_density_pair_term(const FluidBase& f, T r2, T inv_density) {
  const T w = poly6(f.kernel, r2);
  return NormalizedDensityPair<T>{w, w * inv_density};
}

// rho~_i from its sums: mass_sum / volume_sum (rho0 where no neighbour has volume).
SPH_HD float normalized_density_from_sums(const FluidBase& f, float mass_sum, float volume_sum) {
  return volume_sum > 0.0f ? mass_sum / volume_sum : f.rest_density;
}

// Eq. 31 over the carried densities (velocities[j].w = 1 / rho_j), self included.
SPH_HD float gather_normalized_density(const FluidBase& f, const GridView& grid, const Float4* positions,
                                       const Float4* velocities, uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  float mass_sum = 0.0f;
  float volume_sum = 0.0f;
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const float r2 = length_squared(xi - xyz(positions[j]));
    if (r2 >= f.kernel.h2) return;
    const NormalizedDensityPair<float> term = normalized_density_pair_term(f, r2, velocities[j].w);
    mass_sum += term.mass;
    volume_sum += term.volume;
  });
  return normalized_density_from_sums(f, mass_sum, volume_sum);
}

}  // namespace sph
