// The cohesion half of surface tension (Akinci, Akinci and Teschner 2013, "Versatile surface
// tension and adhesion for SPH fluids", eq. 1-2): a short-range pair attraction between fluid
// particles, a_i = -gamma m sum_j C(r_ij) (x_i - x_j) / r_ij, with the spline
//   C(r) = 32 / (pi h^9) * { (h - r)^3 r^3               h/2 < r <= h
//                          { 2 (h - r)^3 r^3 - h^6 / 64  0 < r <= h/2
// (attractive beyond r = 0.27 h, repulsive inside it, zero at and beyond h). It is central and
// antisymmetric, so it is the gradient of a pair potential: momentum is conserved and the total
// energy (kinetic + EOS + cohesion) can only fall. It is what holds a surface particle to the
// drop when it is pushed outward (the pressure is clamped at zero below rest density, and the
// capillary stress acts only along the surface). gamma is not a user parameter: it is set from
// the lattice so that the cohesion's surface energy is the share of sigma it carries
// (fcc_cohesion_surface_energy; docs/physics.md, Surface tension). Akinci's symmetrising factor
// K_ij = 2 rho0 / (rho_i + rho_j) is left out: it would make the force depend on the densities
// and so no longer a pair potential's gradient, and the calibration assumes the plain sum.
#pragma once

#include "host_device.h"
#include "kernels.h"

namespace sph {

// C(r) without its 32 / (pi h^9) (cohesion_coefficient), for 0 < r < h.
template <class T>
SPH_HD T cohesion_spline(T h, T r) {
  const T d = h - r;
  const T p = d * d * d * r * r * r;
  if (T(2) * r > h) return p;
  const T h3 = h * h * h;
  return T(2) * p - h3 * h3 * (T(1) / T(64));
}

// The spline's coefficient 32 / (pi h^9) times `scale`.
template <class T>
SPH_HD T cohesion_coefficient(T h, T scale) {
  const T h3 = h * h * h;
  return scale * T(32) / (kPiOf<T> * h3 * h3 * h3);
}

}  // namespace sph
