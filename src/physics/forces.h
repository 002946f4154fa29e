// Acceleration of a particle from its neighbours: the symmetric pressure force (Monaghan's
// p_i / rho_i^2 + p_j / rho_j^2 form with grad W_spiky; see below why not the thesis's eq. 14),
// viscosity (Mueller's eq. 17 with lap W_viscosity, or Clavet's radial
// impulses, eq. 18-19), surface tension from the colour field (eq. 20-23), and gravity.
// Inputs are the packed records written by the density pass: position.w = p_j and
// velocity.w = 1 / rho_j, so a neighbour costs two 16-byte loads and no division.
//
// The pair term (add_neighbor_acceleration) and the final combination (finish_acceleration)
// are separate so that a backend may walk neighbours its own way (the CUDA backend tests a
// whole run of candidates before evaluating pair terms) and still use this arithmetic.
// Options are template parameters: a world that does not use one compiles it away.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_constants.h"
#include "neighbor_walk.h"
#include "surface_tension_cohesion.h"

namespace sph {

enum class ViscosityMethod : uint32_t { Mueller = 0, Clavet = 1 };

// The pressure force is the symmetric form a_i = -sum_j m (p_i / rho_i^2 + p_j / rho_j^2)
// grad W_ij (Monaghan 1992), not the thesis's eq. 14 (Mueller 2003), -sum_j m (p_i + p_j) /
// (2 rho_j) grad W_ij / rho_i. Both are antisymmetric in i and j (momentum is conserved), but in
// a full neighbourhood sum_j (m / rho_j) grad W_ij vanishes, so eq. 14's p_i half drops out and it
// yields only grad p / 2: a tank at rest then holds twice the hydrostatic pressure and the
// fluid's sound speed is sqrt(k / 2), not the sqrt(k) the step limits assume (tests/validation,
// hydrostatic tank; docs/physics.md). Monaghan's form gives grad p, and with summation density it
// is the form whose work is exactly the change of the equation of state's internal energy, so
// the total energy of a closed box only falls (by viscosity and collisions).
struct AccelerationSums {
  Vec3 pressure;      // sum -(p_j / rho_j^2) grad W_spiky
  Vec3 own_pressure;  // sum -p_i grad W_spiky (times 1 / rho_i^2 in finish_acceleration)
  Vec3 viscosity;     // Mueller: sum (v_j - v_i) / rho_j lap W; Clavet: sum of velocity changes
  Vec3 tension;       // surface tension: sum T_j . grad W_poly6 over neighbours j
  Vec3 gradient;      // surface tension: sum grad W_poly6 (T_i . it in finish_acceleration)
  Vec3 cohesion;      // surface tension: sum C(r) (x_i - x_j) / r (without C's coefficient)
};

SPH_HD AccelerationSums zero_acceleration_sums() {
  const Vec3 zero{0.0f, 0.0f, 0.0f};
  return AccelerationSums{zero, zero, zero, zero, zero, zero};
}

// The capillary stress of a colour-field record applied to a vector g, without sigma:
// T . g = t (g - n^ (n^ . g)) with T = t (I - n^ n^) (Lafaurie et al. 1994) and t = |n| less
// the surface threshold (zero below it): the threshold keeps the noisy normals of interior
// particles out, and the ramp (not a switch) keeps the stress continuous as a particle crosses
// it.
SPH_HD Vec3 surface_stress_times(const FluidConstants& f, const Float4& normal, Vec3 g) {
  const float t = normal.w - f.surface_threshold;
  if (t <= 0.0f) return Vec3{0.0f, 0.0f, 0.0f};
  const Vec3 unit = xyz(normal) * (1.0f / normal.w);
  return (g - unit * dot(unit, g)) * t;
}

// Neighbour j contributes to particle i's forces when within h and not i itself.
SPH_HD bool is_force_neighbor(const FluidConstants& f, float r2, uint32_t i, uint32_t j) {
  return r2 < f.kernel.h2 && j != i;
}

// The contribution of neighbour j (d = x_i - x_j, r2 = |d|^2, within h, j != i).
// normal_i, normal_j: colour-field records (surface tension only; may be null otherwise).
// pair_neighbors = n_i + n_j, the two particles' neighbour counts (Clavet only): they bound
// the impulses, I_ij <= 4 u_ij / (n_i + n_j), so the simultaneous pairwise exchange can only
// remove kinetic energy (the gain from the squared velocity changes stays below the loss);
// and I_ij <= u_ij, so a pair's impulse never reverses its approach.
template <bool kSurfaceTension = false, ViscosityMethod kViscosity = ViscosityMethod::Mueller>
SPH_HD void add_neighbor_acceleration(const FluidConstants& f, const Float4& pi, Vec3 v_i, const Float4& pj,
                                      const Float4& vj, Vec3 d, float r2, AccelerationSums& sums,
                                      float pair_neighbors = 0.0f, const Float4* /*normal_i*/ = nullptr,
                                      const Float4* normal_j = nullptr) {
  const float r = SPH_SQRTF(r2);
  const float inv_rho_j = vj.w;
  // -(p_i / rho_i^2 + p_j / rho_j^2) grad W_spiky; m and 1 / rho_i^2 are applied once in finish.
  const Vec3 grad = spiky_gradient(f.kernel, d, r);
  sums.pressure += grad * (-pj.w * inv_rho_j * inv_rho_j);
  sums.own_pressure += grad * (-pi.w);
  if (kViscosity == ViscosityMethod::Mueller) {
    sums.viscosity += (xyz(vj) - v_i) * (viscosity_laplacian(f.kernel, r) * inv_rho_j);
  } else if (r > 0.0f) {
    // Approaching pairs (u > 0 along i -> j) exchange I = dt (1 - q)(sigma u + beta u^2);
    // i takes half of it, pointing away from j.
    const Vec3 unit = d * (-1.0f / r);
    const float u = dot(v_i - xyz(vj), unit);
    if (u > 0.0f) {
      const float q = r / f.kernel.h;
      float impulse = f.dt * (1.0f - q) * (f.clavet_linear * u + f.clavet_quadratic * u * u);
      // At most u: the pair's own impulse may stop its approach but never reverse it (with
      // few neighbours the energy bound alone, up to 2u, would let a large coefficient turn
      // an inelastic collision into an elastic bounce).
      const float energy_bound = 4.0f * u / pair_neighbors;
      const float bound = energy_bound < u ? energy_bound : u;
      if (impulse > bound) impulse = bound;
      sums.viscosity += unit * (-0.5f * impulse);
    }
  }
  if (kSurfaceTension) {
    const Vec3 g = poly6_gradient(f.kernel, d, r2);
    sums.tension += surface_stress_times(f, *normal_j, g);
    sums.gradient += g;
    if (r > 0.0f) sums.cohesion += d * (cohesion_spline(f.kernel.h, r) / r);
  }
}

template <bool kSurfaceTension = false, ViscosityMethod kViscosity = ViscosityMethod::Mueller>
SPH_HD Vec3 finish_acceleration(const FluidConstants& f, const Float4& vi, const AccelerationSums& sums,
                                const Float4* normal_i = nullptr) {
  // f_i / rho_i with 1/rho_i = vi.w
  const float m_over_rho_i = f.particle_mass * vi.w;
  Vec3 a = (sums.pressure + sums.own_pressure * (vi.w * vi.w)) * f.particle_mass + f.gravity;
  if (kViscosity == ViscosityMethod::Mueller) {
    a += sums.viscosity * (f.viscosity * m_over_rho_i);
  } else if (f.dt > 0.0f) {
    a += sums.viscosity * (1.0f / f.dt);  // the velocity change spread over the substep
  }
  if (kSurfaceTension) {
    // Surface tension as the divergence of the capillary stress sigma T, T = |n| (I - n^ n^)
    // (Lafaurie et al. 1994; Hu and Adams 2006): a tension sigma |n| along the surface and
    // none across it. Its divergence is the CSF force sigma kappa n (Brackbill et al. 1992,
    // Morris 2000, thesis eq. 20-23) plus tangential terms that vanish for constant sigma, so
    // it yields the Laplace pressure without a curvature estimate, which at the particle scale
    // was too noisy to use (it flung particles off). Discretised like the pressure,
    // a_i = (m / rho0^2) sigma S sum_j (T_i + T_j) . grad W_poly6: symmetric in i and j, so
    // momentum is conserved, and on a flat surface the normal parts cancel exactly (T n^ = 0),
    // so a free surface feels no spurious push. The particles sample only the fluid side of
    // the smoothed delta |n|, which across a flat lattice surface integrates to about 0.45
    // instead of 1: S = surface_delta_scale, 1 / that integral, restores the full tension.
    const Vec3 own = surface_stress_times(f, *normal_i, sums.gradient);
    const float scale =
        f.surface_tension * f.surface_delta_scale * f.particle_mass / (f.rest_density * f.rest_density);
    a += (sums.tension + own) * scale;
    // The cohesion (surface_tension_cohesion.h), its share of sigma calibrated on the lattice.
    a += sums.cohesion * (-f.surface_cohesion);
  }
  return a;
}

// The whole gather for particle i. neighbor_counts (the density pass's counts) is read only
// by the Clavet method, normals (the colour-field pass) only with surface tension; either may
// be null otherwise.
template <bool kSurfaceTension, ViscosityMethod kViscosity>
SPH_HD Vec3 gather_acceleration_with(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                     const Float4* velocities, const uint32_t* neighbor_counts,
                                     const Float4* normals, uint32_t i) {
  const Float4 pi = positions[i];
  const Float4 vi = velocities[i];
  const Vec3 xi = xyz(pi);
  const Vec3 v_i = xyz(vi);
  const float n_i = kViscosity == ViscosityMethod::Clavet ? static_cast<float>(neighbor_counts[i]) : 0.0f;
  AccelerationSums sums = zero_acceleration_sums();
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Float4 pj = positions[j];
    const Vec3 d = xi - xyz(pj);
    const float r2 = length_squared(d);
    if (!is_force_neighbor(f, r2, i, j)) return;
    const float pair =
        kViscosity == ViscosityMethod::Clavet ? n_i + static_cast<float>(neighbor_counts[j]) : 0.0f;
    add_neighbor_acceleration<kSurfaceTension, kViscosity>(f, pi, v_i, pj, velocities[j], d, r2, sums, pair,
                                                           kSurfaceTension ? normals + i : nullptr,
                                                           kSurfaceTension ? normals + j : nullptr);
  });
  return finish_acceleration<kSurfaceTension, kViscosity>(f, vi, sums,
                                                          kSurfaceTension ? normals + i : nullptr);
}

// The thesis's default combination: Mueller viscosity, no surface tension.
SPH_HD Vec3 gather_acceleration(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                const Float4* velocities, uint32_t i) {
  return gather_acceleration_with<false, ViscosityMethod::Mueller>(f, grid, positions, velocities, nullptr,
                                                                   nullptr, i);
}

}  // namespace sph
