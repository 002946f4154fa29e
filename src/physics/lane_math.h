// SPDX-License-Identifier: MIT
// The scalar half of the lane vocabulary in which the pair formulas are written once for both a
// scalar (float, or double for the lattice calibration) and a pack of SIMD lanes (the CPU
// backend's src/cpu/cpu_simd_lanes.h). A formula's condition is a value, not a branch:
// select(c, a, b) is `c ? a : b` for a scalar and a per-lane blend for lanes, so one text serves
// both. Both sides are evaluated, which is harmless here: no formula traps, and a discarded
// lane's inf or NaN never reaches a sum. For a scalar every result is bit for bit that of the
// branch it replaces, as long as the condition keeps the branch's own comparison (`r >= h`
// selecting zero, not `r < h` selecting the value: the two differ for NaN).
//
// A pair's distance r = |d| and the division by it (DistanceOf, distance_from_squared) are the one
// place where the device's arithmetic departs from the host's on purpose: the device takes
// 1 / r from one reciprocal square root (rsqrtf, the hardware's approximation, at most 2 ulp)
// and multiplies where the host divides, r = r2 (1 / sqrt(r2)); the host keeps sqrt(r2) and the
// correctly rounded quotient, so the CPU backend's bits are those of the plain formula. Measured
// on an H200 (docs/performance.md, session 4): the force pass is bound by its pair arithmetic,
// and rsqrt in place of an IEEE square root and division cut it by about a fifth.
#pragma once

#include <float.h>

#include "host_device.h"

#if defined(__CUDACC__)
#define SPH_SQRTF sqrtf
#else
#include <cmath>
#define SPH_SQRTF std::sqrt
#endif

namespace sph {

SPH_HD float select(bool c, float a, float b) { return c ? a : b; }
SPH_HD double select(bool c, double a, double b) { return c ? a : b; }

SPH_HD float square_root(float x) { return SPH_SQRTF(x); }
#if defined(__CUDACC__)
SPH_HD double square_root(double x) { return sqrt(x); }
#else
SPH_HD double square_root(double x) { return std::sqrt(x); }
#endif

// 1 / sqrt(x): the device's rsqrtf (at most 2 ulp from the quotient, CUDA C Programming Guide,
// "Mathematical functions"), the correctly rounded quotient on the host. Infinite at x = 0.
SPH_HD float reciprocal_square_root(float x) {
#if defined(__CUDA_ARCH__)
  return rsqrtf(x);
#else
  return 1.0f / SPH_SQRTF(x);
#endif
}
SPH_HD double reciprocal_square_root(double x) {
#if defined(__CUDA_ARCH__)
  return rsqrt(x);
#else
  return 1.0 / square_root(x);
#endif
}

// The distance of a pair and the division by it, for a value type T (a scalar or lanes).
template <class T>
struct DistanceOf {
  T r;      // |d|
  T inv_r;  // 1 / |d| where the device evaluates it (distance_from_squared); unused on the host

  // x / r: on the device x (1 / r), on the host the quotient itself.
  SPH_HD T over(T x) const {
#if defined(__CUDA_ARCH__)
    return x * inv_r;
#else
    return x / r;
#endif
  }
};

// The distance from its square r2 = |d|^2 >= 0. On the device, r2 is raised to the smallest
// normal float before the reciprocal square root: rsqrtf(0) is infinite and 0 * inf would make
// r NaN, whereas this way r2 = 0 gives r = 0 exactly (so a coincident pair meets the formulas'
// r <= 0 guards as on the host) and 1 / r stays finite (about 9.2e18; a term that divides by r
// selects zero at r = 0, so its discarded value never reaches a sum). Every normal r2 keeps its
// own rsqrtf, and a NaN r2 still gives a NaN r, as sqrt does.
template <class T>
SPH_HD DistanceOf<T> distance_from_squared(T r2) {
#if defined(__CUDA_ARCH__)
  const T inv_r = reciprocal_square_root(select(r2 > T(FLT_MIN), r2, T(FLT_MIN)));
  return DistanceOf<T>{r2 * inv_r, inv_r};
#else
  return DistanceOf<T>{square_root(r2), T(0)};
#endif
}

}  // namespace sph
