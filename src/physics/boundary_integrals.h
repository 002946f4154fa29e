// SPDX-License-Identifier: MIT
// Integrals of W_spiky over a solid, in closed form where the solid is simple: the radial
// antiderivatives a quadrature along rays needs (boundary_map.h), and the integral over a half
// space, which is the whole boundary share of a flat wall (boundary_density.h) and the
// calibration's continuous side (core/fcc_lattice.cpp). Written once for float (the physics) and
// double (the calibration and the tests' brute force), like kernels.h.
//
// With W(r) = 15 / (pi h^6) (h - r)^3 (unit integral over the ball of radius h):
//   radial_volume(r) = int_0^r W(t) t^2 dt, so int over a cone of solid angle dOmega between
//     radii r0 and r1 of W dV is dOmega (radial_volume(r1) - radial_volume(r0));
//   half_space(d) = int over {z > d} of W(|x|) dV = a^5 (1.5 h - a) / h^6 with a = h - d, for
//     0 <= d <= h (1/2 at d = 0, 0 at d >= h), and 1 - half_space(-d) for d < 0: the share of
//     the kernel's unit mass that lies beyond a plane at signed distance d.
#pragma once

#include "host_device.h"
#include "kernels.h"

namespace sph {

template <class T>
SPH_HD T spiky_radial_volume(T r, T h) {
  if (r <= T(0)) return T(0);
  if (r > h) r = h;
  const T r2 = r * r, r3 = r2 * r;
  const T h6 = h * h * h * h * h * h;
  // 15 / (pi h^6) int_0^r (h^3 t^2 - 3 h^2 t^3 + 3 h t^4 - t^5) dt
  return T(15) / (kPiOf<T> * h6) *
         (h * h * h * r3 / T(3) - T(3) * h * h * r2 * r2 / T(4) + T(3) * h * r3 * r2 / T(5) - r3 * r3 / T(6));
}

// The share of W_spiky's unit mass beyond a plane at signed distance d from the kernel's centre
// (d > 0: the plane does not contain the centre).
template <class T>
SPH_HD T spiky_half_space(T d, T h) {
  const T ad = d < T(0) ? -d : d;
  T beyond = T(0);
  if (ad < h) {
    const T a = h - ad;
    const T a2 = a * a;
    const T h3 = h * h * h;
    beyond = a2 * a2 * a * (T(1.5) * h - a) / (h3 * h3);
  }
  return d < T(0) ? T(1) - beyond : beyond;
}

// d/dd of spiky_half_space: -(7.5 h a^4 - 6 a^5) / h^6 on both sides (the function is
// symmetric about (0, 1/2), so its derivative is even); -1.5 / h at the plane.
template <class T>
SPH_HD T spiky_half_space_slope(T d, T h) {
  const T ad = d < T(0) ? -d : d;
  if (ad >= h) return T(0);
  const T a = h - ad;
  const T a4 = a * a * a * a;
  const T h3 = h * h * h;
  return -(T(7.5) * h * a4 - T(6) * a4 * a) / (h3 * h3);
}

}  // namespace sph
