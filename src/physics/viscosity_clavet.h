// SPDX-License-Identifier: MIT
// Clavet's viscosity (thesis eq. 18-19; Clavet, Beaudoin & Poulin 2005): radial impulses
// between approaching pairs, q = r / h, u = (v_i - v_j) . r^ > 0,
// I = dt (1 - q)(sigma u + beta u^2), applied half to each particle (sph_clavet_viscosity_params).
// The impulses are bounded per pair, so this method adds no stability ceiling.
#pragma once

#include "fluid_base.h"
#include "force_pair.h"
#include "host_device.h"
#include "param_table.h"
#include "particle_array_spec.h"
#include "world_shape.h"

namespace sph {

struct ClavetViscosity {
  static constexpr const char* kName = "clavet";

  struct Params {
    float linear = 10.0f;    // sigma, 1/s
    float quadratic = 0.0f;  // beta, 1/m
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("linear", &Params::linear, at_least(0.0), ZeroMeans::Value, "1/s"),
      real_field("quadratic", &Params::quadratic, at_least(0.0), ZeroMeans::Value, "1/m"),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float linear;
    float quadratic;
  };
  static Constants make_constants(const Params& p) { return Constants{p.linear, p.quadratic}; }

  // The density pass's neighbour counts (a per-substep array, n_i + n_j bounds the impulses).
  static constexpr ParticleArraySpec kArrays[] = {
      {kArrayNeighborCount, sizeof(uint32_t), ParticleArrayRole::Scratch, 1, nullptr, nullptr}};

  static constexpr bool kReadsNeighborCounts = true;
  static constexpr bool kReadsColourNormals = false;
  template <class T>
  struct SumsOf {
    Vec3Of<T> viscosity;  // sum of i's velocity changes
  };
  using Sums = SumsOf<float>;
  template <class T = float>
  SPH_HD static SumsOf<T> zero_sums() {
    const T zero(0);
    return SumsOf<T>{{zero, zero, zero}};
  }

  // The impulses are bounded by the pair's neighbour counts, I_ij <= 4 u_ij / (n_i + n_j), so
  // the simultaneous pairwise exchange can only remove kinetic energy (the gain from the squared
  // velocity changes stays below the loss); and I_ij <= u_ij, so a pair's impulse never
  // reverses its approach.
  template <class T>
  SPH_HD static void add_pair(const FluidBase& f, const Constants& c, const ForceParticleOf<T>& i,
                              const ForcePairOf<T>& j, SumsOf<T>& s) {
    // Approaching pairs (u > 0 along i -> j, r > 0) exchange I = dt (1 - q)(sigma u + beta u^2);
    // i takes half of it, pointing away from j.
    const T zero(0);
    const Vec3Of<T> unit = j.d * (T(-1.0f) / j.r);
    const T u = dot(i.v - j.v, unit);
    const T q = j.r / f.kernel.h;
    const T impulse = f.dt * (T(1.0f) - q) * (c.linear * u + c.quadratic * u * u);
    // At most u: the pair's own impulse may stop its approach but never reverse it (with
    // few neighbours the energy bound alone, up to 2u, would let a large coefficient turn
    // an inelastic collision into an elastic bounce).
    const T energy_bound = T(4.0f) * u / j.pair_neighbors;
    const T bound = select(energy_bound < u, energy_bound, u);
    const T capped = select(impulse > bound, bound, impulse);
    const Vec3Of<T> change = unit * (T(-0.5f) * capped);
    s.viscosity += j.only(select(!(j.r > zero) || !(u > zero), Vec3Of<T>{zero, zero, zero}, change));
  }
  SPH_HD static void finish(const FluidBase& f, const Constants&, const ForceParticle&, const Sums& s,
                            Vec3& a) {
    if (f.dt > 0.0f) a += s.viscosity * (1.0f / f.dt);  // the velocity change spread over the substep
  }
};

}  // namespace sph
