// SPDX-License-Identifier: MIT
// Rigid placement of colliders, sources and fields: a rotation (unit quaternion) and a
// translation, with interpolation between two poses for substeps inside a frame.
#pragma once

#include "host_device.h"
#include "vec3.h"

namespace sph {

struct Quat {
  float x, y, z, w;  // unit quaternion, w the scalar part
};

struct RigidTransform {
  Vec3 position;
  Quat rotation;
};

SPH_HD Vec3 cross(Vec3 a, Vec3 b) {
  return Vec3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// q v q^-1 for a unit quaternion.
SPH_HD Vec3 rotate(const Quat& q, Vec3 v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = cross(u, v) * 2.0f;
  return v + t * q.w + cross(u, t);
}

SPH_HD Vec3 rotate_inverse(const Quat& q, Vec3 v) { return rotate(Quat{-q.x, -q.y, -q.z, q.w}, v); }

SPH_HD Vec3 to_local(const RigidTransform& t, Vec3 world) {
  return rotate_inverse(t.rotation, world - t.position);
}
SPH_HD Vec3 to_world(const RigidTransform& t, Vec3 local) { return rotate(t.rotation, local) + t.position; }
SPH_HD Vec3 direction_to_world(const RigidTransform& t, Vec3 local) { return rotate(t.rotation, local); }
SPH_HD Vec3 direction_to_local(const RigidTransform& t, Vec3 world) {
  return rotate_inverse(t.rotation, world);
}

// Normalised linear interpolation of rotations along the shorter arc; for the small rotations
// of one frame it is indistinguishable from slerp and has no trigonometry.
SPH_HD Quat nlerp(const Quat& a, Quat b, float s) {
  const float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0.0f) b = Quat{-b.x, -b.y, -b.z, -b.w};
  Quat q{a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s, a.z + (b.z - a.z) * s, a.w + (b.w - a.w) * s};
  const float n = SPH_SQRTF(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  const float inv = n > 0.0f ? 1.0f / n : 1.0f;
  return Quat{q.x * inv, q.y * inv, q.z * inv, q.w * inv};
}

SPH_HD RigidTransform interpolate(const RigidTransform& a, const RigidTransform& b, float s) {
  return RigidTransform{a.position + (b.position - a.position) * s, nlerp(a.rotation, b.rotation, s)};
}

}  // namespace sph
