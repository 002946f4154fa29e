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
  struct Sums {
    Vec3 viscosity;  // sum of i's velocity changes
  };
  SPH_HD static Sums zero_sums() { return Sums{Vec3{0.0f, 0.0f, 0.0f}}; }

  // The impulses are bounded by the pair's neighbour counts, I_ij <= 4 u_ij / (n_i + n_j), so
  // the simultaneous pairwise exchange can only remove kinetic energy (the gain from the squared
  // velocity changes stays below the loss); and I_ij <= u_ij, so a pair's impulse never
  // reverses its approach.
  SPH_HD static void add_pair(const FluidBase& f, const Constants& c, const ForceParticle& i,
                              const ForcePair& j, Sums& s) {
    if (!(j.r > 0.0f)) return;
    // Approaching pairs (u > 0 along i -> j) exchange I = dt (1 - q)(sigma u + beta u^2);
    // i takes half of it, pointing away from j.
    const Vec3 unit = j.d * (-1.0f / j.r);
    const float u = dot(i.v - xyz(j.velocity), unit);
    if (u > 0.0f) {
      const float q = j.r / f.kernel.h;
      float impulse = f.dt * (1.0f - q) * (c.linear * u + c.quadratic * u * u);
      // At most u: the pair's own impulse may stop its approach but never reverse it (with
      // few neighbours the energy bound alone, up to 2u, would let a large coefficient turn
      // an inelastic collision into an elastic bounce).
      const float energy_bound = 4.0f * u / j.pair_neighbors;
      const float bound = energy_bound < u ? energy_bound : u;
      if (impulse > bound) impulse = bound;
      s.viscosity += unit * (-0.5f * impulse);
    }
  }
  SPH_HD static void finish(const FluidBase& f, const Constants&, const ForceParticle&, const Sums& s,
                            Vec3& a) {
    if (f.dt > 0.0f) a += s.viscosity * (1.0f / f.dt);  // the velocity change spread over the substep
  }
};

}  // namespace sph
