// SPDX-License-Identifier: MIT
// A plain 3-vector shared by the CPU and CUDA backends: Vec3 (floats) everywhere, and Vec3Of<T>
// for the pair formulas that are written once for a scalar and for a lane type (lane_math.h):
// the CPU backend's SIMD passes instantiate them with T a pack of 16 lanes.
#pragma once

#include "host_device.h"
#include "lane_math.h"

namespace sph {

template <class T>
struct Vec3Of {
  T x, y, z;
};
using Vec3 = Vec3Of<float>;

// The scalar factor of a product takes the vector's element type without deducing it, so that
// a literal or a float converts as it did before the template (v * 2, or a float into lanes).
template <class T>
struct NonDeduced {
  using type = T;
};
template <class T>
using ScalarOf = typename NonDeduced<T>::type;

SPH_HD Vec3 make_vec3(float x, float y, float z) { return Vec3{x, y, z}; }
template <class T>
SPH_HD Vec3Of<T> operator+(Vec3Of<T> a, Vec3Of<T> b) {
  return Vec3Of<T>{a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
SPH_HD Vec3Of<T> operator-(Vec3Of<T> a, Vec3Of<T> b) {
  return Vec3Of<T>{a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
SPH_HD Vec3Of<T> operator*(Vec3Of<T> a, ScalarOf<T> s) {
  return Vec3Of<T>{a.x * s, a.y * s, a.z * s};
}
template <class T>
SPH_HD Vec3Of<T> operator*(ScalarOf<T> s, Vec3Of<T> a) {
  return Vec3Of<T>{a.x * s, a.y * s, a.z * s};
}
template <class T>
SPH_HD Vec3Of<T>& operator+=(Vec3Of<T>& a, Vec3Of<T> b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
template <class T>
SPH_HD T dot(Vec3Of<T> a, Vec3Of<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
SPH_HD T length_squared(Vec3Of<T> a) {
  return dot(a, a);
}
template <class T>
SPH_HD T length(Vec3Of<T> a) {
  return square_root(dot(a, a));
}

// Per lane: a where c holds, else b (lane_math.h).
template <class Mask, class T>
SPH_HD Vec3Of<T> select(const Mask& c, Vec3Of<T> a, Vec3Of<T> b) {
  return Vec3Of<T>{select(c, a.x, b.x), select(c, a.y, b.y), select(c, a.z, b.z)};
}

}  // namespace sph
