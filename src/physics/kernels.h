// Smoothing kernels of Mueller et al. 2003 (thesis eq. 10-13). Each is zero for r >= h.
// Coefficients depend only on h, so callers compute them once per step (KernelCoefficients)
// and the per-pair functions do no division.
#pragma once

#include "host_device.h"
#include "vec3.h"

namespace sph {

constexpr float kPi = 3.14159265358979323846f;

struct KernelCoefficients {
  float h;
  float h2;
  float poly6;       // 315 / (64 pi h^9)
  float spiky;       // 15 / (pi h^6): W_spiky = spiky (h - r)^3 (the density's pair term)
  float spiky_grad;  // -45 / (pi h^6)
  float visc_lap;    // 45 / (pi h^6)
  float poly6_grad;  // -945 / (32 pi h^9): grad W_poly6 = poly6_grad (h^2 - r^2)^2 r_vec
};

SPH_HD KernelCoefficients make_kernel_coefficients(float h) {
  KernelCoefficients c;
  const float h3 = h * h * h;
  const float h6 = h3 * h3;
  c.h = h;
  c.h2 = h * h;
  c.poly6 = 315.0f / (64.0f * kPi * h6 * h3);
  c.spiky = 15.0f / (kPi * h6);
  c.spiky_grad = -45.0f / (kPi * h6);
  c.visc_lap = 45.0f / (kPi * h6);
  c.poly6_grad = -945.0f / (32.0f * kPi * h6 * h3);
  return c;
}

// W_poly6 from the squared distance: no square root needed for density.
SPH_HD float poly6(const KernelCoefficients& c, float r2) {
  if (r2 >= c.h2) return 0.0f;
  const float d = c.h2 - r2;
  return c.poly6 * d * d * d;
}

// W_spiky(r) = 15 / (pi h^6) (h - r)^3, whose gradient the pressure force uses.
SPH_HD float spiky_value(const KernelCoefficients& c, float r) {
  if (r >= c.h) return 0.0f;
  const float d = c.h - r;
  return c.spiky * d * d * d;
}

// Magnitude factor of grad W_spiky: grad W = spiky_grad_scalar(r) * (r_vec / r).
SPH_HD float spiky_gradient_magnitude(const KernelCoefficients& c, float r) {
  if (r >= c.h) return 0.0f;
  const float d = c.h - r;
  return c.spiky_grad * d * d;
}

// grad W_spiky(r_vec, h) with r_vec = x_i - x_j; zero at r = 0 (direction undefined there).
SPH_HD Vec3 spiky_gradient(const KernelCoefficients& c, Vec3 r_vec, float r) {
  if (r <= 0.0f || r >= c.h) return Vec3{0.0f, 0.0f, 0.0f};
  return r_vec * (spiky_gradient_magnitude(c, r) / r);
}

// Laplacian of W_viscosity.
SPH_HD float viscosity_laplacian(const KernelCoefficients& c, float r) {
  if (r >= c.h) return 0.0f;
  return c.visc_lap * (c.h - r);
}

// grad W_poly6(r_vec) for the colour field of surface tension.
SPH_HD Vec3 poly6_gradient(const KernelCoefficients& c, Vec3 r_vec, float r2) {
  if (r2 >= c.h2) return Vec3{0.0f, 0.0f, 0.0f};
  const float d = c.h2 - r2;
  return r_vec * (c.poly6_grad * d * d);
}

// lap W_poly6(r) = -945 / (32 pi h^9) (h^2 - r^2) (3 h^2 - 7 r^2).
SPH_HD float poly6_laplacian(const KernelCoefficients& c, float r2) {
  if (r2 >= c.h2) return 0.0f;
  return c.poly6_grad * (c.h2 - r2) * (3.0f * c.h2 - 7.0f * r2);
}

// The kernels themselves (not only their derivatives), for normalisation tests and tools.
SPH_HD float spiky(float r, float h) {
  if (r >= h) return 0.0f;
  const float h3 = h * h * h;
  const float d = h - r;
  return 15.0f / (kPi * h3 * h3) * d * d * d;
}

SPH_HD float viscosity_kernel(float r, float h) {
  if (r >= h || r <= 0.0f) return 0.0f;
  const float q = r / h;
  const float h3 = h * h * h;
  return 15.0f / (2.0f * kPi * h3) * (-0.5f * q * q * q + q * q + 0.5f / q - 1.0f);
}

}  // namespace sph
