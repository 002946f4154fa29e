// SPDX-License-Identifier: MIT
// Small vector and quaternion helpers on the C API's types (sph_vec3, sph_quat, sph_transform).
#ifndef SPH_TOOLS_GEOMETRY_H
#define SPH_TOOLS_GEOMETRY_H

#include <cmath>

#include "sph_c.h"

namespace sph_tools {

inline sph_vec3 v3(float x, float y, float z) { return sph_vec3{x, y, z}; }
inline sph_vec3 operator+(sph_vec3 a, sph_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline sph_vec3 operator-(sph_vec3 a, sph_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline sph_vec3 operator*(sph_vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
inline float dot(sph_vec3 a, sph_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline sph_vec3 cross(sph_vec3 a, sph_vec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline float length(sph_vec3 a) { return std::sqrt(dot(a, a)); }
inline sph_vec3 normalize(sph_vec3 a) {
  const float l = length(a);
  return l > 0.0f ? a * (1.0f / l) : a;
}
inline sph_vec3 vmin(sph_vec3 a, sph_vec3 b) {
  return v3(std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z));
}
inline sph_vec3 vmax(sph_vec3 a, sph_vec3 b) {
  return v3(std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z));
}

inline sph_quat quat_identity() { return sph_quat{0.0f, 0.0f, 0.0f, 1.0f}; }
inline sph_quat quat_normalize(sph_quat q) {
  const float l = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return l > 0.0f ? sph_quat{q.x / l, q.y / l, q.z / l, q.w / l} : quat_identity();
}
inline sph_quat quat_axis_angle(sph_vec3 axis, float radians) {
  const sph_vec3 a = normalize(axis);
  const float s = std::sin(0.5f * radians);
  return sph_quat{a.x * s, a.y * s, a.z * s, std::cos(0.5f * radians)};
}
inline sph_quat quat_conjugate(sph_quat q) { return sph_quat{-q.x, -q.y, -q.z, q.w}; }
// Rotates v by the unit quaternion q.
inline sph_vec3 rotate(sph_quat q, sph_vec3 v) {
  const sph_vec3 u = v3(q.x, q.y, q.z);
  const sph_vec3 t = cross(u, v) * 2.0f;
  return v + t * q.w + cross(u, t);
}
// Spherical interpolation along the shorter arc.
inline sph_quat quat_slerp(sph_quat a, sph_quat b, float t) {
  float c = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (c < 0.0f) {
    c = -c;
    b = sph_quat{-b.x, -b.y, -b.z, -b.w};
  }
  float wa = 1.0f - t, wb = t;
  if (c < 0.9995f) {
    const float angle = std::acos(c), s = std::sin(angle);
    wa = std::sin((1.0f - t) * angle) / s;
    wb = std::sin(t * angle) / s;
  }
  return quat_normalize(
      sph_quat{wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w});
}

// World point of a local point, and back (the rotation is normalised first).
inline sph_vec3 to_world(const sph_transform& t, sph_vec3 local) {
  return rotate(quat_normalize(t.rotation), local) + t.position;
}
inline sph_vec3 to_local(const sph_transform& t, sph_vec3 world) {
  return rotate(quat_conjugate(quat_normalize(t.rotation)), world - t.position);
}

}  // namespace sph_tools

#endif
