// SPDX-License-Identifier: MIT
// A plain 3-vector of floats shared by the CPU and CUDA backends.
#pragma once

#include "host_device.h"

#if defined(__CUDACC__)
#define SPH_SQRTF sqrtf
#else
#include <cmath>
#define SPH_SQRTF std::sqrt
#endif

namespace sph {

struct Vec3 {
  float x, y, z;
};

SPH_HD Vec3 make_vec3(float x, float y, float z) { return Vec3{x, y, z}; }
SPH_HD Vec3 operator+(Vec3 a, Vec3 b) { return Vec3{a.x + b.x, a.y + b.y, a.z + b.z}; }
SPH_HD Vec3 operator-(Vec3 a, Vec3 b) { return Vec3{a.x - b.x, a.y - b.y, a.z - b.z}; }
SPH_HD Vec3 operator*(Vec3 a, float s) { return Vec3{a.x * s, a.y * s, a.z * s}; }
SPH_HD Vec3 operator*(float s, Vec3 a) { return Vec3{a.x * s, a.y * s, a.z * s}; }
SPH_HD Vec3& operator+=(Vec3& a, Vec3 b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
SPH_HD float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SPH_HD float length_squared(Vec3 a) { return dot(a, a); }
SPH_HD float length(Vec3 a) { return SPH_SQRTF(dot(a, a)); }

}  // namespace sph
