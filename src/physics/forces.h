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

// The neighbour sums of one particle; finish_acceleration turns them into a_i.
struct AccelerationSums {
  Vec3 pressure;   // sum_j -(p_i + p_j) / rho_j grad W_spiky (the 1/2 and m applied at the end)
  Vec3 viscosity;  // sum_j (v_j - v_i) / rho_j lap W_visc
};

SPH_HD AccelerationSums zero_acceleration_sums() {
  return AccelerationSums{Vec3{0.0f, 0.0f, 0.0f}, Vec3{0.0f, 0.0f, 0.0f}};
}

// Whether candidate j contributes to particle i's force, given r2 = |x_i - x_j|^2.
SPH_HD bool is_force_neighbor(const FluidConstants& f, float r2, uint32_t i, uint32_t j) {
  return !(r2 >= f.kernel.h2) && j != i;
}

// Adds neighbour j to particle i's sums. pi, vi: particle i's records (p_i in pi.w); pj, vj:
// neighbour j's (p_j in pj.w, 1/rho_j in vj.w); d = x_i - x_j and r2 = |d|^2.
SPH_HD void add_neighbor_acceleration(const FluidConstants& f, const Float4& pi, Vec3 v_i, const Float4& pj,
                                      const Float4& vj, Vec3 d, float r2, AccelerationSums& sums) {
  const float r = SPH_SQRTF(r2);
  const float inv_rho_j = vj.w;
  // -(p_i + p_j) / (2 rho_j) grad W_spiky; the 1/2 and m are applied once in finish_acceleration.
  sums.pressure += spiky_gradient(f.kernel, d, r) * (-(pi.w + pj.w) * inv_rho_j);
  // (v_j - v_i) / rho_j lap W_visc
  sums.viscosity += (xyz(vj) - v_i) * (viscosity_laplacian(f.kernel, r) * inv_rho_j);
}

// a_i = f_i / rho_i + g, with 1/rho_i = vi.w.
SPH_HD Vec3 finish_acceleration(const FluidConstants& f, const Float4& vi, const AccelerationSums& sums) {
  const float m_over_rho_i = f.particle_mass * vi.w;
  return sums.pressure * (0.5f * m_over_rho_i) + sums.viscosity * (f.viscosity * m_over_rho_i) + f.gravity;
}

SPH_HD Vec3 gather_acceleration(const FluidConstants& f, const GridView& grid, const Float4* positions,
                                const Float4* velocities, uint32_t i) {
  const Float4 pi = positions[i];
  const Float4 vi = velocities[i];
  const Vec3 xi = xyz(pi);
  const Vec3 v_i = xyz(vi);
  AccelerationSums sums = zero_acceleration_sums();
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Float4 pj = positions[j];
    const Vec3 d = xi - xyz(pj);
    const float r2 = length_squared(d);
    if (!is_force_neighbor(f, r2, i, j)) return;
    add_neighbor_acceleration(f, pi, v_i, pj, velocities[j], d, r2, sums);
  });
  return finish_acceleration(f, vi, sums);
}

}  // namespace sph
