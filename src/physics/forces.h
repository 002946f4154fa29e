// Acceleration of a particle from its neighbours: the symmetric pressure force (thesis eq. 14
// with grad W_spiky), Mueller's viscosity (eq. 17 with lap W_viscosity), and gravity.
// Inputs are the packed records written by the density pass: position.w = p_j and
// velocity.w = 1 / rho_j, so a neighbour costs two 16-byte loads and no division.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_constants.h"
#include "neighbor_walk.h"

namespace sph {

SPH_HD Vec3 gather_acceleration(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                const Float4* velocities, uint32_t i) {
  const Float4 pi = positions[i];
  const Float4 vi = velocities[i];
  const Vec3 xi = xyz(pi);
  const Vec3 v_i = xyz(vi);
  Vec3 pressure_sum{0.0f, 0.0f, 0.0f};
  Vec3 viscosity_sum{0.0f, 0.0f, 0.0f};
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Float4 pj = positions[j];
    const Vec3 d = xi - xyz(pj);
    const float r2 = length_squared(d);
    if (r2 >= f.kernel.h2 || j == i) return;
    const Float4 vj = velocities[j];
    const float r = SPH_SQRTF(r2);
    const float inv_rho_j = vj.w;
    // -(p_i + p_j) / (2 rho_j) grad W_spiky; the 1/2 and m are applied once outside the loop.
    pressure_sum += spiky_gradient(f.kernel, d, r) * (-(pi.w + pj.w) * inv_rho_j);
    // (v_j - v_i) / rho_j lap W_visc
    viscosity_sum += (xyz(vj) - v_i) * (viscosity_laplacian(f.kernel, r) * inv_rho_j);
  });
  // f_i / rho_i with 1/rho_i = vi.w
  const float m_over_rho_i = f.particle_mass * vi.w;
  return pressure_sum * (0.5f * m_over_rho_i) + viscosity_sum * (f.viscosity * m_over_rho_i) + f.gravity;
}

}  // namespace sph
