// SPDX-License-Identifier: MIT
// Density diffusion (SPH_FEATURE_DENSITY_DIFFUSION): the delta-SPH term of Molteni & Colagrossi
// 2009 with the dynamic-density correction of Fourtakas et al. 2019, added to the rate of the
// carried density:
//   D_i = delta h c0 sum_j psi_ij . grad_i W_ij V_j,
//   psi_ij = 2 (rho_ji - rho^H_ji) x_ji / (r^2 + eta^2),   x_ji = x_j - x_i, rho_ji = rho_j - rho_i,
//   rho^H_ji = rho0 g . x_ji / c0^2,                         eta^2 = 0.01 h^2, V_j = m / rho_j.
// With grad_i W_ij = -|W'(r)| x_ji / r (W_spiky, the density's kernel) the pair term is
//   2 (rho_ji - rho^H_ji) |W'(r)| r / (r^2 + eta^2) m / rho_j,
// a positive weight times the density difference: D_i pulls rho_i towards its neighbours'.
//
// Why the correction: the plain term (rho^H = 0) diffuses any density gradient, the hydrostatic
// one too, so a tank at rest slowly loses its stratification at the walls and free surface
// (Fourtakas et al. 2019, fig. 3). rho^H_ji is the hydrostatic density difference between the
// two particles (dp = rho0 g . dx, dp = c0^2 drho); subtracting it makes the term vanish on the
// hydrostatic profile rho = rho0 (1 + g . x / c0^2) + const. This is Fourtakas's
// rho0 ((1 + rho0 g z_ij / B)^(1/gamma) - 1) to first order in rho0 g z_ij / B over a kernel
// width (1e-4 here: a term of 1e-8 dropped); for the ideal-gas law, p = c0^2 (rho - rho0), it is
// exact. c0 is the equation of state's speed of sound at rest density (speed_of_sound).
//
// Conservation: the pair term times V_i is antisymmetric in (i, j) (rho^H_ij = -rho^H_ji), so
// sum_i V_i D_i = 0: the diffusion moves density (volume) between particles, the volume-weighted
// total is kept to rounding.
//
// Which density: the term is a part of the continuity equation d rho / dt, so it needs a density
// that is integrated in time. The summation (density.h) has no history: it is a function of the
// current positions, and whatever a rate adds to it is gone at the next pass. The integrated
// density here is the normalised density's carried one (density_normalization.h): rho_i =
// g_i sum_j m W_ij, g_i carried. So the feature requires SPH_FEATURE_NORMALIZED_DENSITY, and it
// takes the place of that feature's Shepard filter: delta-SPH was introduced as the alternative to
// re-initialising the density with a Shepard filter (Colagrossi & Landrini 2003), which removes
// the noise but is not conservative and, applied every pass, dissipates density waves (the closed
// box loses 78 % of its energy in 1.2 s, docs/physics.md); on top of the filter the diffusion
// measured nothing (a settled tank's within-layer pressure noise 9.8 Pa with the filter, 10.3 Pa
// with both). D_i is applied through the factor once per substep, after the first density pass
// (for RK4 its stage 0): rho_i <- rho_i + dt D_i and g_i <- g_i (rho_i + dt D_i) / rho_i (a Lie
// splitting of the continuity equation's diffusion part, forward Euler: explicit, stable for
// delta c0 dt / h well below 1, which the acoustic ceiling c0 dt <= 0.4 h gives).
#pragma once

#include <stdint.h>

#include "density_normalization.h"
#include "float4_types.h"
#include "fluid_base.h"
#include "host_device.h"
#include "kernels.h"
#include "neighbor_walk.h"
#include "param_table.h"
#include "world_shape.h"

namespace sph {

struct DensityDiffusion {
  static constexpr const char* kName = "density_diffusion";

  struct Params {
    float delta = 0.1f;  // Molteni & Colagrossi's delta; 0.1 is their (and DualSPHysics's) default
  };
  // 0 takes the default (a world with the feature and no diffusion is a world without the
  // feature); above 1 the explicit update can overshoot (delta c0 dt / h grows past the
  // term's stability bound at the acoustic ceiling).
  static constexpr ParamField<Params> kFields[] = {
      real_field("delta", &Params::delta, above_up_to(0.0, 1.0), ZeroMeans::Default, ""),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float coefficient;  // 2 delta h c0 m, kg m^2/s (the pair term's prefactor)
    Vec3 hydrostatic;   // rho0 g / c0^2, kg/m^4: rho^H_ji = hydrostatic . x_ji
    float eta2;         // 0.01 h^2, m^2
    float sound_speed;  // c0, m/s (the carried factor's relaxation, density_normalization.h)
  };
  // c0: the equation of state's speed of sound at rest density; gravity: the world's.
  static Constants make_constants(const Params& p, const WorldShape& shape, float sound_speed, Vec3 gravity) {
    Constants c{};
    const float h = shape.kernel_radius;
    c.coefficient = 2.0f * p.delta * h * sound_speed * shape.particle_mass;
    const float c2 = sound_speed * sound_speed;
    c.hydrostatic = c2 > 0.0f ? gravity * (shape.rest_density / c2) : Vec3{0.0f, 0.0f, 0.0f};
    c.eta2 = 0.01f * h * h;
    c.sound_speed = sound_speed;
    return c;
  }
  // No arrays of its own: the pass writes the diffused density into the normalised density's
  // side array (free once the filtered densities are published) and republishes from it.
};

// D_i's pair term for neighbour j: x_ji = x_j - x_i at distance r (< h, j != i), rho_ji =
// rho_j - rho_i, inv_density_j = 1 / rho_j. T is float or a pack of lanes (lane_math.h).
template <class T>
SPH_HD T density_diffusion_pair_term(const FluidBase& f, const DensityDiffusion::Constants& c,
                                     const Vec3Of<T>& x_ji, T r, T rho_ji, T inv_density_j) {
  const T dynamic = rho_ji - dot(Vec3Of<T>{T(c.hydrostatic.x), T(c.hydrostatic.y), T(c.hydrostatic.z)}, x_ji);
  const T weight = spiky_gradient_magnitude(f.kernel, r) * r / (r * r + T(c.eta2));
  // spiky_gradient_magnitude is W'(r) <= 0; the term is + |W'| ..., so minus it.
  return T(-c.coefficient) * dynamic * weight * inv_density_j;
}

// D_i (kg/m^3/s) over the published densities (velocities[j].w = 1 / rho_j), self excluded.
SPH_HD float gather_density_diffusion(const FluidBase& f, const DensityDiffusion::Constants& c,
                                      const GridView& grid, const Float4* positions, const Float4* velocities,
                                      uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  const float rho_i = 1.0f / velocities[i].w;
  float rate = 0.0f;
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 x_ji = xyz(positions[j]) - xi;
    const float r2 = length_squared(x_ji);
    if (r2 >= f.kernel.h2 || j == i) return;
    const float inv_rho_j = velocities[j].w;
    rate += density_diffusion_pair_term(f, c, x_ji, square_root(r2), 1.0f / inv_rho_j - rho_i, inv_rho_j);
  });
  return rate;
}

// The diffused density and the factor that carries it (rho > 0, rate from the gather), the
// factor then relaxed towards 1 where the neighbourhood is full (density_normalization.h:
// without it the diffusion hides the compression it smooths away in the factors).
struct DiffusedDensity {
  float density;
  float factor;
};
SPH_HD DiffusedDensity diffused_density(const FluidBase& f, const DensityDiffusion::Constants& c,
                                        float density, float factor, float rate, float dt) {
  const float summed = density / factor;  // the kernel sum, walls' share included
  const float diffused = factor * ((density + dt * rate) / density);
  const float relaxed =
      relaxed_density_factor(f, summed, diffused, density_factor_relaxation(dt, c.sound_speed, f.kernel.h));
  return DiffusedDensity{relaxed * summed, relaxed};
}

}  // namespace sph
