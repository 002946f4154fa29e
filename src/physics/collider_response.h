// SPDX-License-Identifier: MIT
// Particles against one SDF collider (thesis 3.4.2, eq. 33-37), for static, kinematic (a
// pose interpolated inside the frame) and deforming (a surface velocity field) colliders.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "host_device.h"
#include "rigid_transform.h"
#include "sdf_sampling.h"
#include "vec3.h"

namespace sph {

struct ColliderView {
  SdfGridView sdf;
  RigidTransform pose_start;  // at the start of the frame
  RigidTransform pose_end;    // at the end of the frame (equal to pose_start when static)
  Vec3 linear_velocity;       // of the pose's origin over the frame, m/s
  Vec3 angular_velocity;      // world frame, rad/s
  float restitution;          // share of the normal approach speed returned, [0, 1]
  float friction;             // Coulomb coefficient (unless the SDF has a friction field)
  float stickiness;           // acceleration toward the surface within one kernel radius, m/s^2
  float sign;                 // +1: solid where the SDF is negative; -1 (inverted): a container
  uint32_t moving;            // 0 for a static collider: one pose, no collider velocity
  uint32_t deforming;         // the SDF carries a velocity field
  // The asset's boundary-density correction for the world's h (boundary_map.h), one Float4 per
  // SDF voxel in the memory the SDF view points to; null without SPH_FEATURE_BOUNDARY_DENSITY.
  const Float4* boundary_map;
  // The point the loads' torque is taken about, in the collider's frame (collider_loads.h).
  Vec3 load_point;
};

struct SubstepTime {
  float s0, s1;      // start and end of the substep as fractions of the frame, [0, 1]
  float tau0, tau1;  // the same in seconds since the start of the frame
  float dt;          // tau1 - tau0
};

// Where a world point sits in the collider's field at a frame fraction: the pose interpolated
// to that time, and for a deforming collider the field advected back by its velocity.
struct ColliderSample {
  RigidTransform pose;
  Vec3 local;
  float distance;  // signed, with the collider's sign applied (negative = in the solid)
};

SPH_HD ColliderSample sample_collider(const ColliderView& c, Vec3 world, float s, float tau) {
  ColliderSample out;
  out.pose = c.moving ? interpolate(c.pose_start, c.pose_end, s) : c.pose_start;
  out.local = to_local(out.pose, world);
  if (c.deforming) out.local = out.local - sample_velocity(c.sdf, out.local) * tau;
  out.distance = c.sign * sample_distance(c.sdf, out.local);
  return out;
}

SPH_HD Vec3 collider_normal(const ColliderView& c, const ColliderSample& s) {
  return direction_to_world(s.pose, sample_normal(c.sdf, s.local) * c.sign);
}

// Velocity of the collider's surface material at a world point.
SPH_HD Vec3 collider_velocity(const ColliderView& c, const ColliderSample& s, Vec3 world) {
  Vec3 v{0.0f, 0.0f, 0.0f};
  if (c.moving) v = c.linear_velocity + cross(c.angular_velocity, world - s.pose.position);
  if (c.deforming) v += direction_to_world(s.pose, sample_velocity(c.sdf, s.local));
  return v;
}

// The push-out's search (push_out): after the first step, the step jumps to at least a 64th of a
// voxel and doubles (10 times reach 8 voxels; the flat cell is one voxel deep), then 16 halvings
// of the bracket end within 1/65536 of it (a face's float rounding, the usual reason for a search
// there, brackets the push's depth: 2 mm gives 3e-8 m).
constexpr int kPushOutDoublings = 10;
constexpr float kPushOutFirstJump = 1.0f / 64.0f;  // of the smallest voxel
constexpr int kPushOutHalvings = 16;

// Moves a particle that lies inside the solid (now.distance < 0) out along the field's normal to
// its zero level; now becomes the sample there. One step of -distance is exact where the field is
// a distance (unit gradient), but inside a solid's edge the trilinear field is flat (in the edge's
// cell of a box whose faces lie on samples it is -voxel (1 - fx) (1 - fy): the product of the
// depths below both faces over a voxel, far less than either depth). That step then left the
// particle inside; the next substep it started inside, so the path's contact was skipped and it
// was pushed out by as little again: it stayed caught in the solid (docs/validation.md, "The
// submerged box: particles caught inside its edges"). So while the particle is still inside, the
// step grows, and the last bracket [inside, outside] is bisected keeping the outside end: the
// particle ends on the zero level or just outside it. Where the first step leaves the solid (a
// flat face, the usual case) nothing changes; where the search finds no outside (a zero normal)
// the particle is left where the first step put it, as before.
SPH_HD Vec3 push_out(const ColliderView& c, const SubstepTime& t, Vec3 x, ColliderSample& now) {
  const Vec3 n = collider_normal(c, now);
  float inside = 0.0f, outside = -now.distance;
  Vec3 y = x + n * outside;
  ColliderSample out = sample_collider(c, y, t.s1, t.tau1);
  for (int k = 0; k < kPushOutDoublings && out.distance < 0.0f; ++k) {
    inside = outside;
    outside = SPH_FMAXF(2.0f * outside, kPushOutFirstJump * c.sdf.min_voxel_size);
    y = x + n * outside;
    out = sample_collider(c, y, t.s1, t.tau1);
  }
  if (out.distance < 0.0f) {
    y = x + n * -now.distance;
    now = sample_collider(c, y, t.s1, t.tau1);
    return y;
  }
  for (int k = 0; k < kPushOutHalvings && inside > 0.0f; ++k) {
    const float mid = 0.5f * (inside + outside);
    const Vec3 ym = x + n * mid;
    const ColliderSample s = sample_collider(c, ym, t.s1, t.tau1);
    if (s.distance < 0.0f) {
      inside = mid;
    } else {
      outside = mid;
      y = ym;
      out = s;
    }
  }
  now = out;
  return y;
}

// Resolves one particle after integration moved it from x_old to x (velocity v) during the
// substep. Returns true if it touched the collider.
SPH_HD bool collide_particle(const ColliderView& c, const SubstepTime& t, float kernel_radius, Vec3 x_old,
                             Vec3& x, Vec3& v) {
  ColliderSample now = sample_collider(c, x, t.s1, t.tau1);
  if (now.distance >= 0.0f) {
    // Stickiness (thesis 4.4.2.2): a pull toward the surface that fades over one kernel radius.
    if (c.stickiness > 0.0f && now.distance < kernel_radius) {
      const Vec3 n = collider_normal(c, now);
      v = v - n * (c.stickiness * (1.0f - now.distance / kernel_radius) * t.dt);
    }
    return false;
  }
  const ColliderSample before = sample_collider(c, x_old, t.s0, t.tau0);
  if (before.distance > 0.0f) {
    // The particle moved into the object: the contact point by interpolating the distances
    // along its path; the rest of the path slides along the surface.
    const float f = before.distance / (before.distance - now.distance);
    const Vec3 contact = x_old + (x - x_old) * f;
    const Vec3 n = collider_normal(c, now);
    const Vec3 rest = x - contact;
    x = contact + (rest - n * dot(rest, n));
    now = sample_collider(c, x, t.s1, t.tau1);
  }
  if (now.distance < 0.0f) x = push_out(c, t, x, now);  // the object moved into it, or the slide ended inside
  const Vec3 n = collider_normal(c, now);
  const Vec3 vc = collider_velocity(c, now, x);
  const Vec3 rel = v - vc;
  const float vn = dot(rel, n);
  if (vn < 0.0f) {
    // Restitution on the normal part; Coulomb friction on the tangential part, limited by the
    // normal impulse. A collider faster along the normal than the particle carries it along.
    const Vec3 tangential = rel - n * vn;
    const float vt = length(tangential);
    const float mu = sample_friction(c.sdf, now.local, c.friction);
    const float impulse = (1.0f + c.restitution) * (-vn);
    const float keep = vt > 0.0f ? (1.0f - mu * impulse / vt) : 0.0f;
    v = vc + n * (-c.restitution * vn) + tangential * (keep > 0.0f ? keep : 0.0f);
  }
  return true;
}

}  // namespace sph
