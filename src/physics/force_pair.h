// SPDX-License-Identifier: MIT
// What a force term (a method's part of the acceleration, forces.h) sees of particle i and of
// one neighbour j. The composer fills these once per particle and once per pair, so that every
// term reads the same values and a term that is compiled out costs nothing.
// Records as the density pass leaves them: position.w = p, velocity.w = 1 / rho.
#pragma once

#include "float4_types.h"
#include "vec3.h"

namespace sph {

struct ForceParticle {
  Float4 position;       // x_i, p_i
  Float4 velocity;       // v_i, 1 / rho_i
  Vec3 x;                // x_i
  Vec3 v;                // v_i
  float neighbor_count;  // n_i, when a term reads neighbour counts (else 0)
  const Float4* normal;  // i's colour-field record, when a term reads them (else null)
};

struct ForcePair {
  Float4 position;       // x_j, p_j
  Float4 velocity;       // v_j, 1 / rho_j
  Vec3 d;                // x_i - x_j
  float r2;              // |d|^2 < h^2, j != i
  float r;               // |d|
  float pair_neighbors;  // n_i + n_j, when a term reads neighbour counts (else 0)
  const Float4* normal;  // j's colour-field record, when a term reads them (else null)
};

}  // namespace sph
