// SPDX-License-Identifier: MIT
// What a force term (a method's part of the acceleration, forces.h) sees of particle i and of
// one neighbour j. The composer fills these once per particle and once per pair, so that every
// term reads the same values and a term that is compiled out costs nothing.
//
// Both are templates on the value type T (lane_math.h): float for one pair at a time (the scalar
// gather, the CUDA kernels), or a pack of lanes, one candidate j per lane (the CPU backend's SIMD
// passes). A term adds its pair's contribution through j.only(...), which keeps the lanes that
// hold a force neighbour and gives zero in the others; for a scalar pair (always a neighbour) it
// is the value itself, so the scalar sums are those of the plain loop bit for bit.
#pragma once

#include "float4_types.h"
#include "vec3.h"

namespace sph {

template <class T>
struct ForceParticleOf {
  Vec3Of<T> x;       // x_i
  T pressure;        // p_i
  Vec3Of<T> v;       // v_i
  T inv_density;     // 1 / rho_i
  T neighbor_count;  // n_i, when a term reads neighbour counts (else 0)
  Vec3Of<T> normal;  // i's colour-field normal n_i, when a term reads them (else 0)
  T normal_length;   // |n_i| (else 0)
};
using ForceParticle = ForceParticleOf<float>;

template <class T>
struct ForcePairOf {
  using Mask = decltype(T() < T());
  T pressure;        // p_j
  Vec3Of<T> v;       // v_j
  T inv_density;     // 1 / rho_j
  Vec3Of<T> d;       // x_i - x_j
  T r2;              // |d|^2 < h^2, j != i (in the lanes of `neighbor`)
  T r;               // |d|
  T pair_neighbors;  // n_i + n_j, when a term reads neighbour counts (else 0)
  Vec3Of<T> normal;  // j's colour-field normal, when a term reads them (else 0)
  T normal_length;   // |n_j| (else 0)
  Mask neighbor;     // the lanes that hold a force neighbour (true for a scalar pair)

  // A pair term as it enters a sum: the value where j is a force neighbour, else zero. Sums
  // start at +0 and so are never -0, hence adding a lane's +0 leaves its sum's bits unchanged.
  SPH_HD T only(T value) const { return select(neighbor, value, T(0)); }
  SPH_HD Vec3Of<T> only(Vec3Of<T> value) const {
    const T zero(0);
    return select(neighbor, value, Vec3Of<T>{zero, zero, zero});
  }
};
using ForcePair = ForcePairOf<float>;

}  // namespace sph
