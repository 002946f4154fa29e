// SPDX-License-Identifier: MIT
// Density by summation (thesis eq. 9) and the pressure it implies.
//
// The pair terms use W_spiky, the kernel whose gradient the pressure force uses (forces.h), not
// the thesis's W_poly6: with rho_i = m (w0 + sum_{j != i} W_ij), Monaghan's symmetric pressure
// force -m sum_j (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij is exactly minus the gradient of the
// equation of state's internal energy sum_i m e(rho_i) (de/drho = p / rho^2) only when grad W_ij
// is the gradient of the same W. With W_poly6 in the density and grad W_spiky in the force the
// force does work that no energy pays for: measured, a closed box of sloshing water gained 18 %
// (58 % at a finer resolution) of its energy and two colliding blobs in free space up to 18 %,
// whatever the step size, and a tank of water at rest kept churning at about 1 m/s
// (docs/validation.md, "Closed box"). The self term w0 is a constant (its gradient is zero, so
// the force never sees it), set per world so that the FCC lattice at the world's spacing has
// exactly rest density with the lattice's particle mass (fcc_density_self_weight): W_spiky(0)
// itself is a poor quadrature weight at 1.8 spacings (the lattice sum would be 21 % high).
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_base.h"
#include "neighbor_walk.h"

namespace sph {

struct DensitySample {
  float density;            // rho_i = m (w0 + sum_{j != i} W_spiky(|x_i - x_j|, h))
  uint32_t neighbor_count;  // particles with r < h, self excluded
};

// The pair term of the sum for a neighbour at squared distance r2 (< h^2, j != i): W_spiky(r).
// T is float or a pack of lanes (lane_math.h; the CPU backend's SIMD density pass).
template <class T>
SPH_HD T density_pair_term(const FluidBase& f, T r2) {
  return spiky_value(f.kernel, square_root(r2));
}

// The sample from the sum of the pair terms and the neighbour count.
SPH_HD DensitySample density_from_sum(const FluidBase& f, float sum, uint32_t neighbors) {
  return DensitySample{f.particle_mass * (f.density_self_weight + sum), neighbors};
}

// positions: sorted particle records (xyz used, w ignored). Returns rho_i for particle i.
SPH_HD DensitySample gather_density(const FluidBase& f, const GridView& grid, const Float4* positions,
                                    uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  float sum = 0.0f;
  uint32_t neighbors = 0;
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 < f.kernel.h2 && j != i) {
      sum += density_pair_term(f, r2);
      ++neighbors;
    }
  });
  return density_from_sum(f, sum, neighbors);
}

}  // namespace sph
