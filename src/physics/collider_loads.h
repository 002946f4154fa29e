// SPDX-License-Identifier: MIT
// Loads (SPH_FEATURE_COLLIDER_LOADS): the force and torque of the fluid on each collider, as
// the momentum the fluid gives it. Per substep, every particle adds per collider
//   - the wall's pressure reaction (SPH_FEATURE_BOUNDARY_DENSITY): the wall accelerates the
//     particle by -c grad rho_b (c = p / rho^2 in WCSPH's force pass, boundary_density.h; kappa /
//     rho in DFSPH's velocity update), so the collider receives +m c grad rho_b over that share
//     of the step: wall_reaction_impulse();
//   - the contact impulse of the collision response (always): m (v_before - v_after), the
//     momentum collide_particle() (collider_response.h) takes from the particle, stickiness
//     included: contact_impulse().
// Each impulse J at a particle x adds J to the collider's linear impulse and (x - p) x J to its
// angular impulse about the load point p (a point fixed in the collider's frame, posed at the
// time of the impulse). A frame's loads are the sums over its substeps divided by the frame's
// time: the time average of the force and torque, so the impulses balance the fluid's momentum
// change exactly (docs/physics.md "Loads on colliders").
//
// Determinism: particles are summed in blocks of kLoadBlock in storage order (a fixed tree on
// the GPU, a loop on the CPU), then the blocks in order, in double, into the frame's sums; so the
// result depends on neither the thread count nor the scheduling.
//
// Who calls what:
//   - WCSPH force pass / RK4 stages: wall_reaction_impulse(collider_boundary_share(...).gradient,
//     m, p_i / rho_i^2 * weight * dt), weight 1 (Euler) or rk4_weight(stage);
//   - the collision response pass: contact_impulse(m, v before, v after) per collider, in the
//     order collide_particle() visits them;
//   - DFSPH, once per substep after both solves: wall_reaction_impulse(collider gradient, m,
//     p_i / rho_i^2 * dt) with p = (k + k_v / dt) rho^2 (dfsph_pressure: the sums both solves
//     carry), which is the sum of what every velocity update of both solves applied
//     (v_i -= dt k_i grad rho_b each, the warm start included; with SPH_DFSPH_CORRECTED_GRADIENT
//     the particle received only corrected_wall_share of it where the correction acts, which this
//     sum does not know, so it over-counts there: docs/physics.md), at the substep's start; the
//     impulses of its contact clamp (respect_contact after each velocity update of both solves
//     and after the non-pressure accelerations), summed per particle (add_clamp into
//     kArrayDfsphContactImpulse) and given to the collider of the particle's contact at the
//     substep's start; and its collision response's contacts as above.
#pragma once

#include <stdint.h>

#include "collider_response.h"
#include "float4_types.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

struct ColliderLoads {
  static constexpr const char* kName = "collider_loads";
};

// DFSPH with the loads: per particle, xyz the velocity changes its contact clamps made in this
// substep (the momentum it gave the wall, over m), w the index of its contact's collider (a
// float: exact below 2^24 colliders). Scratch, found anew each substep (dfsph_passes.h).
constexpr const char* kArrayDfsphContactImpulse = "dfsph_contact_impulse";

// Particles per block of the loads reduction (both backends; the CUDA kernel's block size).
constexpr uint32_t kLoadBlock = 256;

// One collider's impulses of a block of particles (or a sum of blocks).
struct LoadImpulse {
  Vec3 linear;   // N s
  Vec3 angular;  // N m s, about the collider's load point
};

SPH_HD LoadImpulse zero_load_impulse() { return LoadImpulse{Vec3{0.0f, 0.0f, 0.0f}, Vec3{0.0f, 0.0f, 0.0f}}; }

SPH_HD LoadImpulse operator+(const LoadImpulse& a, const LoadImpulse& b) {
  return LoadImpulse{a.linear + b.linear, a.angular + b.angular};
}

// The load point in the world at frame fraction s (it moves with the collider).
SPH_HD Vec3 load_point_at(const ColliderView& c, float s) {
  const RigidTransform pose = c.moving ? interpolate(c.pose_start, c.pose_end, s) : c.pose_start;
  return to_world(pose, c.load_point);
}

// Adds impulse j, applied at world point x, about the load point p.
SPH_HD void add_load(LoadImpulse& sum, Vec3 j, Vec3 x, Vec3 p) {
  sum.linear += j;
  sum.angular += cross(x - p, j);
}

// The collider's share of the wall's pressure: the particle was accelerated by
// -coefficient * grad rho_b over the time coefficient_dt is taken over, so the collider gets
// m * coefficient_dt * grad rho_b (coefficient_dt = p / rho^2 * share of dt in WCSPH).
SPH_HD Vec3 wall_reaction_impulse(Vec3 collider_gradient, float mass, float coefficient_dt) {
  return collider_gradient * (mass * coefficient_dt);
}

// DFSPH's contact clamp (kArrayDfsphContactImpulse): a particle's record starts each substep as
// no_clamp(its contact's collider); each clamp of a velocity from `before` to `after` adds the
// change (add_clamp); the loads pass gives clamp_impulse to collider clamp_collider (none: the
// count, for a particle without a contact, which no clamp changes).
SPH_HD Float4 no_clamp(uint32_t collider) { return Float4{0.0f, 0.0f, 0.0f, static_cast<float>(collider)}; }
SPH_HD void add_clamp(Float4& record, Vec3 before, Vec3 after) {
  record = Float4{record.x + (before.x - after.x), record.y + (before.y - after.y),
                  record.z + (before.z - after.z), record.w};
}
SPH_HD uint32_t clamp_collider(const Float4& record, uint32_t colliders) {
  return record.w >= 0.0f && record.w < static_cast<float>(colliders) ? static_cast<uint32_t>(record.w)
                                                                      : colliders;
}
SPH_HD Vec3 clamp_impulse(float mass, const Float4& record) { return xyz(record) * mass; }

// The momentum a collision response took from a particle.
SPH_HD Vec3 contact_impulse(float mass, Vec3 velocity_before, Vec3 velocity_after) {
  return (velocity_before - velocity_after) * mass;
}

}  // namespace sph
