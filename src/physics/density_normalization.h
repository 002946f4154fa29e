// Normalised density (thesis eq. 31): rho~_i = sum_j m W_ij / sum_j (m / rho_j) W_ij. Near a
// free surface the plain sum misses neighbours and reads low; dividing by the kernel's
// discrete partition of unity corrects that deficit. Needs rho_j from a first density pass
// (velocity.w = 1 / rho_j).
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_constants.h"
#include "neighbor_walk.h"

namespace sph {

SPH_HD float gather_normalized_density(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                       const Float4* velocities, uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  float mass_sum = 0.0f;
  float volume_sum = 0.0f;
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const float r2 = length_squared(xi - xyz(positions[j]));
    if (r2 >= f.kernel.h2) return;
    const float w = poly6(f.kernel, r2);
    mass_sum += w;
    volume_sum += w * velocities[j].w;
  });
  return volume_sum > 0.0f ? mass_sum / volume_sum : f.rest_density;
}

}  // namespace sph
