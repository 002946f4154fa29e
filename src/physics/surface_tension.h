// SPDX-License-Identifier: MIT
// Surface tension (SPH_FEATURE_SURFACE_TENSION): the thesis's colour field (eq. 20-23) turned
// into a capillary stress, plus a short-range cohesion, both calibrated on the FCC lattice so
// that sigma is the physical N/m (docs/physics.md, Surface tension; sph_surface_tension_params).
//
// Colour normal (Morris 2000; thesis eq. 20-21): n_i = grad c_i = sum_j (m / rho0)
// grad W_poly6(x_i - x_j) (the rest volume m / rho0 stands for each neighbour's m / rho_j, as in
// the lattice calibration), computed after the density pass. It points into the fluid and its
// length marks the surface (about 1/h there, near zero inside). Written as (n, |n|) so
// neighbours read both in one load.
//
// Capillary stress: a_i = (m / rho0^2) sigma S sum_j (T_i + T_j) . grad W_poly6 with
// T = t (I - n^ n^) (Lafaurie et al. 1994; Hu and Adams 2006), t = |n| less the surface
// threshold: a tension sigma |n| along the surface and none across it. Its divergence is the CSF
// force sigma kappa n (Brackbill et al. 1992, Morris 2000) plus tangential terms that vanish for
// constant sigma, so it yields the Laplace pressure without a curvature estimate, which at the
// particle scale was too noisy to use (it flung particles off). Symmetric in i and j, so
// momentum is conserved, and on a flat surface the normal parts cancel exactly (T n^ = 0), so a
// free surface feels no spurious push. The particles sample only the fluid side of the smoothed
// delta |n|, which across a flat lattice surface integrates to about 0.45 instead of 1:
// S = delta_scale, (1 - kCohesionShare) / that integral, restores the stress's share of sigma.
//
// Cohesion (Akinci, Akinci and Teschner 2013, "Versatile surface tension and adhesion for SPH
// fluids", eq. 1-2): a pair attraction a_i = -gamma m sum_j C(r_ij) (x_i - x_j) / r_ij with
//   C(r) = 32 / (pi h^9) * { (h - r)^3 r^3               h/2 < r <= h
//                          { 2 (h - r)^3 r^3 - h^6 / 64  0 < r <= h/2
// (attractive beyond r = 0.27 h, repulsive inside it, zero at and beyond h). Central and
// antisymmetric, so it is the gradient of a pair potential: momentum is conserved and the total
// energy (kinetic + EOS + cohesion) can only fall. It holds a surface particle to the drop when
// it is pushed outward (the pressure is clamped at zero below rest density, and the stress acts
// only along the surface). gamma is set from the lattice so that the cohesion's surface energy
// is its share of sigma (fcc_cohesion_lattice). Akinci's factor K_ij = 2 rho0 / (rho_i + rho_j)
// is left out: it would make the force depend on the densities and so no longer a pair
// potential's gradient, and the calibration assumes the plain sum.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_base.h"
#include "force_pair.h"
#include "host_device.h"
#include "kernels.h"
#include "neighbor_walk.h"
#include "param_table.h"
#include "particle_array_spec.h"
#include "world_shape.h"

namespace sph {

// C(r) without its 32 / (pi h^9) (cohesion_coefficient), for 0 < r < h.
template <class S, class T>
SPH_HD T cohesion_spline(S h, T r) {
  const T d = h - r;
  const T p = d * d * d * r * r * r;
  const S h3 = h * h * h;
  return select(T(2) * r > h, p, T(2) * p - T(h3 * h3 * (S(1) / S(64))));
}

// The spline's coefficient 32 / (pi h^9) times `scale`.
template <class T>
SPH_HD T cohesion_coefficient(T h, T scale) {
  const T h3 = h * h * h;
  return scale * T(32) / (kPiOf<T> * h3 * h3 * h3);
}

struct SurfaceTension {
  static constexpr const char* kName = "surface_tension";

  struct Params {
    float coefficient = 0.0728f;    // sigma, N/m (water at 20 C)
    float normal_threshold = 0.0f;  // |grad c| above which the stress acts, 1/m; 0 = 0.2 / h
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("coefficient", &Params::coefficient, at_least(0.0), ZeroMeans::Value, "N/m"),
      real_field("normal_threshold", &Params::normal_threshold, at_least(0.0), ZeroMeans::Derived, "1/m"),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float coefficient;  // sigma, N/m
    float threshold;    // |grad c| above which the stress acts, 1/m
    float delta_scale;  // S: the stress's share of sigma / the flat lattice surface's delta integral
    float cohesion;     // gamma m 32 / (pi h^9), from the cohesion's share of sigma, 1/(m^5 s^2)
  };

  // The cohesion carries this share of sigma and the capillary stress the rest; each share is
  // calibrated on the flat FCC lattice at the world's spacing (the cohesion by its separation
  // energy, the stress by its sampled delta integral). 15 % is measured, not derived: more
  // cohesion makes the lattice stiff and plastic (a mode-2 drop oscillation overdamped at 50 %,
  // its mean shape drifting at 20 %), less holds the surface less (10 %: period 9 % fast).
  static constexpr float kCohesionShare = 0.15f;

  static Constants make_constants(const Params& p, const WorldShape& s, const LatticeSums& lattice) {
    Constants c;
    c.coefficient = p.coefficient;
    c.threshold = p.normal_threshold > 0.0f ? p.normal_threshold : 0.2f / s.kernel_radius;
    const float share = kCohesionShare;
    const double integral = lattice.surface_delta_integral(s.particle_spacing, s.kernel_radius, c.threshold);
    c.delta_scale = integral > 0.0 ? static_cast<float>((1.0 - share) / integral) : 0.0f;
    const double energy = lattice.cohesion_surface_energy(s.particle_spacing, s.kernel_radius);
    const double h = s.kernel_radius, m = s.particle_mass;
    const double gamma_m = energy > 0.0 ? share * c.coefficient / (m * energy) : 0.0;
    c.cohesion = static_cast<float>(cohesion_coefficient(h, gamma_m));
    return c;
  }

  // The colour-field records, rebuilt after every density pass.
  static constexpr ParticleArraySpec kArrays[] = {
      {kArrayColourNormal, sizeof(Float4), ParticleArrayRole::Scratch, 1, nullptr, nullptr}};

  // The capillary stress of a colour-field record (n, |n|) applied to a vector g, without sigma:
  // T . g = t (g - n^ (n^ . g)) with t = |n| less the threshold (zero below it): the threshold
  // keeps the noisy normals of interior particles out, and the ramp (not a switch) keeps the
  // stress continuous as a particle crosses it.
  template <class T>
  SPH_HD static Vec3Of<T> stress_times(const Constants& c, Vec3Of<T> normal, T normal_length, Vec3Of<T> g) {
    const T zero(0);
    const T t = normal_length - c.threshold;
    const Vec3Of<T> unit = normal * (T(1.0f) / normal_length);
    return select(t <= zero, Vec3Of<T>{zero, zero, zero}, (g - unit * dot(unit, g)) * t);
  }

  static constexpr bool kReadsNeighborCounts = false;
  static constexpr bool kReadsColourNormals = true;
  template <class T>
  struct SumsOf {
    Vec3Of<T> tension;   // sum T_j . grad W_poly6 over neighbours j
    Vec3Of<T> gradient;  // sum grad W_poly6 (T_i . it in finish)
    Vec3Of<T> cohesion;  // sum C(r) (x_i - x_j) / r (without C's coefficient)
  };
  using Sums = SumsOf<float>;
  template <class T = float>
  SPH_HD static SumsOf<T> zero_sums() {
    const T zero(0);
    const Vec3Of<T> zero3{zero, zero, zero};
    return SumsOf<T>{zero3, zero3, zero3};
  }
  template <class T>
  SPH_HD static void add_pair(const FluidBase& f, const Constants& c, const ForceParticleOf<T>&,
                              const ForcePairOf<T>& j, SumsOf<T>& s) {
    const T zero(0);
    const Vec3Of<T> g = poly6_gradient(f.kernel, j.d, j.r2);
    s.tension += j.only(stress_times(c, j.normal, j.normal_length, g));
    s.gradient += j.only(g);
    const Vec3Of<T> pull = j.d * (cohesion_spline(f.kernel.h, j.r) / j.r);
    s.cohesion += j.only(select(j.r > zero, pull, Vec3Of<T>{zero, zero, zero}));
  }
  SPH_HD static void finish(const FluidBase& f, const Constants& c, const ForceParticle& i, const Sums& s,
                            Vec3& a) {
    const Vec3 own = stress_times(c, i.normal, i.normal_length, s.gradient);
    const float scale = c.coefficient * c.delta_scale * f.particle_mass / (f.rest_density * f.rest_density);
    a += (s.tension + own) * scale;
    a += s.cohesion * (-c.cohesion);
  }
};

// The colour normal's pair term for a neighbour at d = x_i - x_j, r2 = |d|^2 (< h^2, j != i).
template <class T>
SPH_HD Vec3Of<T> colour_normal_pair_term(const FluidBase& f, Vec3Of<T> d, T r2) {
  return poly6_gradient(f.kernel, d, r2) * (1.0f / f.rest_density);
}

// The colour-field record (n_i, |n_i|) of particle i.
SPH_HD Float4 gather_colour_normal(const FluidBase& f, const GridView& grid, const Float4* positions,
                                   const Float4* /*velocities*/, uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  Vec3 n{0.0f, 0.0f, 0.0f};
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 >= f.kernel.h2 || j == i) return;
    n += colour_normal_pair_term(f, d, r2);
  });
  n = n * f.particle_mass;
  return make_float4_record(n, length(n));
}

}  // namespace sph
