// SPDX-License-Identifier: MIT
// Elasticity and plasticity (thesis 4.4.2.1): springs between neighbouring particles whose
// rest lengths yield and creep, after Clavet, Beaudoin & Poulin 2005, "Particle-based
// viscoelastic fluid simulation", section 5, written as accelerations for this solver's
// integrators instead of Clavet's position displacements.
//
// Springs are made once for each particle, at its first substep: to its nearest neighbours
// within the link radius, so the rest shape is the shape the particles were spawned in.
// Each spring is stored on both of its particles (a fixed list of kSpringSlots slots per
// particle: the partner's storage index and the rest length L), so every particle gathers
// its own spring force without atomics. Both copies see the same distance bit for bit
// (x_i - x_j is exactly -(x_j - x_i)) and so update L identically: the forces are equal and
// opposite (momentum is conserved to round-off) and the result does not depend on the order
// or the thread that computes it.
//
//   a_i = sum_springs [ -k (1 - L/h) (r - L) - c (v_i - v_j) . r^ ] r^,  r^ = (x_i - x_j) / r
//
// Plasticity (Clavet eq. in section 5.1, once per substep): with the tolerable deformation
// d = gamma L,  r > L + d:  L += dt alpha (r - L - d);   r < L - d:  L -= dt alpha (L - d - r).
// A spring whose rest length grows past h is dropped (Clavet's rule; the (1 - L/h) factor has
// faded its force to zero by then), as is a spring whose partner a sink removed.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "host_device.h"
#include "neighbor_walk.h"
#include "param_table.h"
#include "particle_array_spec.h"
#include "vec3.h"
#include "world_shape.h"

namespace sph {

// Springs one particle can hold: an FCC lattice has 12 nearest neighbours; the rest is room
// for particles spawned off a lattice.
constexpr uint32_t kSpringSlots = 16;
constexpr uint32_t kNoSpring = 0xffffffffu;        // an empty slot / no partner
constexpr uint32_t kNoPendingLinks = 0xffffffffu;  // link_from when no particle waits for springs

struct SpringList {
  uint32_t partner[kSpringSlots];  // storage index of the other end, kNoSpring when empty
  float rest[kSpringSlots];        // rest length L, m
};

struct SpringConstants {
  float stiffness;          // k, 1/s^2 (acceleration per metre of stretch)
  float damping;            // c, 1/s (acceleration per m/s of separation speed)
  float yield_ratio;        // gamma, dimensionless
  float plasticity;         // alpha, 1/s; 0 = purely elastic
  float link_radius_sq;     // springs are made to neighbours closer than this, m^2
  float kernel_radius;      // h: a spring whose rest length exceeds it is dropped
  float inv_kernel_radius;  // 1 / h
};

SPH_HD SpringList empty_spring_list() {
  SpringList s;
  for (uint32_t k = 0; k < kSpringSlots; ++k) {
    s.partner[k] = kNoSpring;
    s.rest[k] = 0.0f;
  }
  return s;
}

// Particles with an id at or above link_from have not made their springs yet (ids only grow).
SPH_HD bool waits_for_springs(uint32_t id, uint32_t link_from) { return id >= link_from; }

// The list of a particle moved by a permutation: partners follow new_index_of_old (kNoSpring
// for a particle that is gone, e.g. removed by a sink, which drops the spring).
SPH_HD SpringList remap_spring_list(const SpringList& in, const uint32_t* new_index_of_old) {
  SpringList out;
  for (uint32_t k = 0; k < kSpringSlots; ++k) {
    const uint32_t p = in.partner[k];
    out.partner[k] = p == kNoSpring ? kNoSpring : new_index_of_old[p];
    out.rest[k] = out.partner[k] == kNoSpring ? 0.0f : in.rest[k];
  }
  return out;
}

// Candidate order: nearer first, then the lower id. Both ends compute the same r2 bit for bit.
SPH_HD bool spring_candidate_before(float r2_a, uint32_t id_a, float r2_b, uint32_t id_b) {
  return r2_a < r2_b || (r2_a == r2_b && id_a < id_b);
}

// Linking, pass 1: the partners particle i would like, nearest first, into out[kSpringSlots]
// (kNoSpring-padded). A particle that waits for springs may pick any neighbour within the link
// radius; one that has its springs picks only among those that wait, for its free slots.
// A spring is made in pass 2 when both ends picked each other, a symmetric rule.
SPH_HD void spring_candidates(const SpringConstants& c, const GridView& grid, const Float4* positions,
                              const uint32_t* ids, uint32_t link_from, const SpringList& own, uint32_t i,
                              uint32_t* out) {
  const bool i_waits = waits_for_springs(ids[i], link_from);
  float best_r2[kSpringSlots];
  uint32_t best_id[kSpringSlots];
  uint32_t best_j[kSpringSlots];
  uint32_t free_slots = 0;
  for (uint32_t k = 0; k < kSpringSlots; ++k) {
    free_slots += own.partner[k] == kNoSpring ? 1u : 0u;
    out[k] = kNoSpring;
    best_r2[k] = 0.0f;
    best_id[k] = 0;
    best_j[k] = kNoSpring;
  }
  if (free_slots == 0) return;
  uint32_t count = 0;
  const Vec3 xi = xyz(positions[i]);
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    if (j == i) return;
    const uint32_t id_j = ids[j];
    if (!i_waits && !waits_for_springs(id_j, link_from)) return;  // both linked: settled
    const float r2 = length_squared(xi - xyz(positions[j]));
    if (!(r2 < c.link_radius_sq)) return;
    if (count == free_slots && !spring_candidate_before(r2, id_j, best_r2[count - 1], best_id[count - 1]))
      return;
    uint32_t k = count < free_slots ? count++ : free_slots - 1;
    while (k > 0 && spring_candidate_before(r2, id_j, best_r2[k - 1], best_id[k - 1])) {
      best_r2[k] = best_r2[k - 1];
      best_id[k] = best_id[k - 1];
      best_j[k] = best_j[k - 1];
      --k;
    }
    best_r2[k] = r2;
    best_id[k] = id_j;
    best_j[k] = j;
  });
  for (uint32_t k = 0; k < count; ++k) out[k] = best_j[k];
}

// Linking, pass 2: particle i keeps each candidate j that also picked i, in free slots, with
// the current distance as rest length. candidates holds pass 1's lists of all particles.
SPH_HD void spring_link(const Float4* positions, const uint32_t* candidates, uint32_t i, SpringList& own) {
  const uint32_t* mine = candidates + static_cast<uint64_t>(i) * kSpringSlots;
  const Vec3 xi = xyz(positions[i]);
  uint32_t slot = 0;
  for (uint32_t k = 0; k < kSpringSlots; ++k) {
    const uint32_t j = mine[k];
    if (j == kNoSpring) break;
    const uint32_t* theirs = candidates + static_cast<uint64_t>(j) * kSpringSlots;
    bool mutual = false;
    for (uint32_t m = 0; m < kSpringSlots && theirs[m] != kNoSpring; ++m) mutual = mutual || theirs[m] == i;
    if (!mutual) continue;
    while (own.partner[slot] != kNoSpring) ++slot;  // pass 1 picked at most the free slots
    own.partner[slot] = j;
    own.rest[slot] = SPH_SQRTF(length_squared(xi - xyz(positions[j])));
  }
}

// Clavet's plastic flow of a rest length L at length r over dt (alpha dt capped at 1, so a
// large alpha moves L onto the yield surface and no further).
SPH_HD float plastic_rest_length(const SpringConstants& c, float rest, float r, float dt) {
  float rate = dt * c.plasticity;
  if (rate > 1.0f) rate = 1.0f;
  const float tolerance = c.yield_ratio * rest;
  if (r > rest + tolerance) return rest + rate * (r - rest - tolerance);
  if (r < rest - tolerance) return rest - rate * (rest - tolerance - r);
  return rest;
}

// The spring acceleration of particle i (sorted positions and velocities). kUpdateRest: once
// per substep (its first force evaluation), let the rest lengths flow and drop the springs
// whose rest length passed h, writing the list back; other evaluations only read it.
template <bool kUpdateRest>
SPH_HD Vec3 spring_acceleration(const SpringConstants& c, const Float4* positions, const Float4* velocities,
                                uint32_t i, SpringList& own, float dt) {
  const Vec3 xi = xyz(positions[i]);
  const Vec3 vi = xyz(velocities[i]);
  Vec3 a{0.0f, 0.0f, 0.0f};
  for (uint32_t k = 0; k < kSpringSlots; ++k) {
    const uint32_t j = own.partner[k];
    if (j == kNoSpring) continue;
    const Vec3 d = xi - xyz(positions[j]);
    const float r = SPH_SQRTF(length_squared(d));
    float rest = own.rest[k];
    if (kUpdateRest && c.plasticity > 0.0f) {
      rest = plastic_rest_length(c, rest, r, dt);
      if (rest > c.kernel_radius) {
        own.partner[k] = kNoSpring;
        own.rest[k] = 0.0f;
        continue;
      }
      own.rest[k] = rest;
    }
    if (!(r > 0.0f)) continue;
    const Vec3 unit = d * (1.0f / r);
    float magnitude = -c.stiffness * (1.0f - rest * c.inv_kernel_radius) * (r - rest);
    if (c.damping > 0.0f) magnitude -= c.damping * dot(vi - xyz(velocities[j]), unit);
    a += unit * magnitude;
  }
  return a;
}

// The explicit scheme's limits for springs, as the fluid's stability ceilings (pressure_force.h,
// viscosity_mueller.h): dt <= 0.5 / sqrt(kSpringSlots k) for the stiffness (a particle with
// kSpringSlots springs has its fastest mode at omega^2 <= 2 kSpringSlots k by Gershgorin,
// (1 - L/h) <= 1, and symplectic Euler needs omega dt < 2) and dt <= 2 / (kSpringSlots c) for the
// damping. Measured on a free blob with random velocities (fixed steps, 4000 of them;
// docs/physics.md): stiffness alone is stable at 2x its limit and blows up at 2.5x; damping alone
// is stable at 2x its limit and blows up at 3x. So both leave a margin of 2. 0 when springs
// impose none.
constexpr float kSpringStabilityFactor = 0.5f;
constexpr float kSpringDampingStabilityFactor = 2.0f;

SPH_HD float spring_stability_ceiling(float stiffness, float damping) {
  float dt = 0.0f;
  if (stiffness > 0.0f) dt = kSpringStabilityFactor / SPH_SQRTF(static_cast<float>(kSpringSlots) * stiffness);
  if (damping > 0.0f) {
    const float damped = kSpringDampingStabilityFactor / (static_cast<float>(kSpringSlots) * damping);
    if (dt == 0.0f || damped < dt) dt = damped;
  }
  return dt;
}

// The method (SPH_FEATURE_SPRINGS): its parameters, constants, arrays and step ceiling.
struct Springs {
  static constexpr const char* kName = "springs";

  struct Params {
    float stiffness = 1e4f;    // k, 1/s^2
    float link_radius = 0.0f;  // m; 0 = 1.2 x particle spacing, at most h
    float yield_ratio = 0.1f;  // gamma
    float plasticity = 0.0f;   // alpha, 1/s; 0 = elastic
    float damping = 0.0f;      // c, 1/s
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("stiffness", &Params::stiffness, at_least(0.0), ZeroMeans::Value, "1/s^2"),
      real_field("link_radius", &Params::link_radius, at_least(0.0), ZeroMeans::Derived, "m"),
      real_field("yield_ratio", &Params::yield_ratio, within(0.0, 1.0), ZeroMeans::Value, ""),
      real_field("plasticity", &Params::plasticity, at_least(0.0), ZeroMeans::Value, "1/s"),
      real_field("damping", &Params::damping, at_least(0.0), ZeroMeans::Value, "1/s"),
  };
  static bool check(const Params& p, const WorldShape& s, ParamConflict& out) {
    if (p.link_radius > s.kernel_radius) {
      out = ParamConflict{"link_radius", p.link_radius, "m is above the kernel radius", nullptr,
                          s.kernel_radius};
      return false;
    }
    return true;
  }

  using Constants = SpringConstants;
  // The link radius a world uses: the parameter, or 1.2 particle spacings (the FCC lattice's
  // nearest neighbours only), never more than h.
  static float link_radius(const Params& p, const WorldShape& s) {
    const float r = p.link_radius > 0.0f ? p.link_radius : 1.2f * s.particle_spacing;
    return r < s.kernel_radius ? r : s.kernel_radius;
  }
  static Constants make_constants(const Params& p, const WorldShape& s) {
    Constants c;
    c.stiffness = p.stiffness;
    c.damping = p.damping;
    c.yield_ratio = p.yield_ratio;
    c.plasticity = p.plasticity;
    const float link = link_radius(p, s);
    c.link_radius_sq = link * link;
    c.kernel_radius = s.kernel_radius;
    c.inv_kernel_radius = 1.0f / s.kernel_radius;
    return c;
  }
  static float stability_ceiling(const Params& p) { return spring_stability_ceiling(p.stiffness, p.damping); }

  // Each particle's list (partners as storage indices, rewritten at every reorder) and the lowest
  // id that waits for its springs (one word per world) are carried state; the link candidates
  // and the evaluation's accelerations (Float4 for aligned loads) are rebuilt by each spring pass.
  static void rewrite_partners(void* element, const uint32_t* new_index_of_old) {
    SpringList* list = static_cast<SpringList*>(element);
    *list = remap_spring_list(*list, new_index_of_old);
  }
  inline static const SpringList kEmptyList = empty_spring_list();
  static constexpr uint32_t kNoLinksPending = kNoPendingLinks;
  inline static const ParticleArraySpec kArrays[] = {
      {kArraySprings, sizeof(SpringList), ParticleArrayRole::Carried, 1, &kEmptyList, &rewrite_partners},
      {kArraySpringLinkFrom, sizeof(uint32_t), ParticleArrayRole::Carried, 0, &kNoLinksPending, nullptr},
      {kArraySpringCandidates, sizeof(uint32_t), ParticleArrayRole::Scratch, kSpringSlots, nullptr, nullptr},
      {kArraySpringAcceleration, sizeof(Float4), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
  };
};

}  // namespace sph
