// SPDX-License-Identifier: MIT
// Smoothing kernels of Mueller et al. 2003 (thesis eq. 10-13). Each is zero for r >= h.
// Coefficients depend only on h, so callers compute them once per step (KernelCoefficients)
// and the per-pair functions do no division.
//
// Written once for any scalar type: float for the physics both backends run, double for the
// lattice calibration (core/fcc_lattice.cpp) and the constants derived from it, so that a
// change here moves the calibration with it (no coefficient is typed twice).
#pragma once

#include "host_device.h"
#include "vec3.h"

namespace sph {

template <class T>
constexpr T kPiOf = static_cast<T>(3.14159265358979323846L);
constexpr float kPi = kPiOf<float>;

template <class T>
struct KernelCoefficientsOf {
  T h;
  T h2;
  T poly6;       // 315 / (64 pi h^9)
  T spiky;       // 15 / (pi h^6): W_spiky = spiky (h - r)^3 (the density's pair term)
  T spiky_grad;  // -45 / (pi h^6)
  T visc_lap;    // 45 / (pi h^6)
  T poly6_grad;  // -945 / (32 pi h^9): grad W_poly6 = poly6_grad (h^2 - r^2)^2 r_vec
};
using KernelCoefficients = KernelCoefficientsOf<float>;

template <class T>
SPH_HD KernelCoefficientsOf<T> make_kernel_coefficients(T h) {
  KernelCoefficientsOf<T> c;
  const T h3 = h * h * h;
  const T h6 = h3 * h3;
  c.h = h;
  c.h2 = h * h;
  c.poly6 = T(315) / (T(64) * kPiOf<T> * h6 * h3);
  c.spiky = T(15) / (kPiOf<T> * h6);
  c.spiky_grad = T(-45) / (kPiOf<T> * h6);
  c.visc_lap = T(45) / (kPiOf<T> * h6);
  c.poly6_grad = T(-945) / (T(32) * kPiOf<T> * h6 * h3);
  return c;
}

// The per-pair functions below take the coefficients' scalar S (float, or double for the
// calibration) and a value type T that is S or a pack of lanes (lane_math.h): their conditions
// are selects, so one text serves the scalar gathers, the CUDA kernels and the CPU's SIMD passes.

// W_poly6 from the squared distance: no square root needed for density.
template <class S, class T>
SPH_HD T poly6(const KernelCoefficientsOf<S>& c, T r2) {
  const T d = c.h2 - r2;
  return select(r2 >= c.h2, T(0), c.poly6 * d * d * d);
}

// W_spiky(r) = 15 / (pi h^6) (h - r)^3, whose gradient the pressure force uses.
template <class S, class T>
SPH_HD T spiky_value(const KernelCoefficientsOf<S>& c, T r) {
  const T d = c.h - r;
  return select(r >= c.h, T(0), c.spiky * d * d * d);
}

// Magnitude factor of grad W_spiky: grad W = spiky_grad_scalar(r) * (r_vec / r).
template <class S, class T>
SPH_HD T spiky_gradient_magnitude(const KernelCoefficientsOf<S>& c, T r) {
  const T d = c.h - r;
  return select(r >= c.h, T(0), c.spiky_grad * d * d);
}

// grad W_spiky(r_vec, h) with r_vec = x_i - x_j; zero at r = 0 (direction undefined there).
template <class S, class T>
SPH_HD Vec3Of<T> spiky_gradient(const KernelCoefficientsOf<S>& c, Vec3Of<T> r_vec, T r) {
  const T zero(0);
  return select((r <= zero) || (r >= c.h), Vec3Of<T>{zero, zero, zero},
                r_vec * (spiky_gradient_magnitude(c, r) / r));
}

// Laplacian of W_viscosity.
template <class S, class T>
SPH_HD T viscosity_laplacian(const KernelCoefficientsOf<S>& c, T r) {
  return select(r >= c.h, T(0), c.visc_lap * (c.h - r));
}

// The scalar of grad W_poly6 = poly6_gradient_factor(r^2) r_vec.
template <class S, class T>
SPH_HD T poly6_gradient_factor(const KernelCoefficientsOf<S>& c, T r2) {
  const T d = c.h2 - r2;
  return select(r2 >= c.h2, T(0), c.poly6_grad * d * d);
}

// grad W_poly6(r_vec) for the colour field of surface tension.
template <class S, class T>
SPH_HD Vec3Of<T> poly6_gradient(const KernelCoefficientsOf<S>& c, Vec3Of<T> r_vec, T r2) {
  const T zero(0);
  return select(r2 >= c.h2, Vec3Of<T>{zero, zero, zero}, r_vec * poly6_gradient_factor(c, r2));
}

// lap W_poly6(r) = -945 / (32 pi h^9) (h^2 - r^2) (3 h^2 - 7 r^2).
template <class S, class T>
SPH_HD T poly6_laplacian(const KernelCoefficientsOf<S>& c, T r2) {
  return select(r2 >= c.h2, T(0), c.poly6_grad * (c.h2 - r2) * (T(3) * c.h2 - T(7) * r2));
}

// The kernels themselves (not only their derivatives), for normalisation tests and tools.
template <class T>
SPH_HD T spiky(T r, T h) {
  if (r >= h) return T(0);
  const T h3 = h * h * h;
  const T d = h - r;
  return T(15) / (kPiOf<T> * h3 * h3) * d * d * d;
}

template <class T>
SPH_HD T viscosity_kernel(T r, T h) {
  if (r >= h || r <= T(0)) return T(0);
  const T q = r / h;
  const T h3 = h * h * h;
  return T(15) / (T(2) * kPiOf<T> * h3) * (T(-0.5) * q * q * q + q * q + T(0.5) / q - T(1));
}

}  // namespace sph
