// The colour-field normal of surface tension (Morris 2000; thesis eq. 20-21):
// n_i = grad c_i = sum_j (m / rho_j) grad W_poly6(x_i - x_j). It points into the fluid and its
// length marks the surface (about 1/h there, near zero inside). Needs rho_j from the density
// pass (velocity.w = 1 / rho_j). Written as (n, |n|) so neighbours read both in one load.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_constants.h"
#include "neighbor_walk.h"

namespace sph {

SPH_HD Float4 gather_colour_normal(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                   const Float4* /*velocities*/, uint32_t i) {
  const Vec3 xi = xyz(positions[i]);
  Vec3 n{0.0f, 0.0f, 0.0f};
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 >= f.kernel.h2 || j == i) return;
    n += poly6_gradient(f.kernel, d, r2) * (1.0f / f.rest_density);
  });
  n = n * f.particle_mass;
  return make_float4_record(n, length(n));
}

}  // namespace sph
