// Density by summation (thesis eq. 9 with W_poly6) and the pressure it implies.
#pragma once

#include <stdint.h>

#include "equation_of_state.h"
#include "float4_types.h"
#include "fluid_constants.h"
#include "neighbor_walk.h"

namespace sph {

struct DensitySample {
  float density;            // rho_i = sum_j m W_poly6(|x_i - x_j|, h), self included
  uint32_t neighbor_count;  // particles with r < h, self excluded
};

// positions: sorted particle records (xyz used, w ignored). Returns rho_i for particle i.
SPH_HD DensitySample gather_density(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                    uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  float sum = 0.0f;
  uint32_t neighbors = 0;
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 < f.kernel.h2) {
      sum += poly6(f.kernel, r2);
      neighbors += (j != i) ? 1u : 0u;
    }
  });
  return DensitySample{f.particle_mass * sum, neighbors};
}

}  // namespace sph
