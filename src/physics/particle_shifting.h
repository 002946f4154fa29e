// SPDX-License-Identifier: MIT
// Fickian particle shifting for DFSPH (Lind et al. 2012, Skillen et al. 2013): after each substep
// particle i moves, beside x += dt v, by
//   dr_i = -C h^2 grad C_i,   grad C_i = (sum_j m grad W_ij + grad rho_b(x_i)) / rho0,
// C_i = sum_j V_j W_ij (V_j = m / rho0; the walls' share rho_b / rho0 with the walls in the
// density), the gradient with the pressure force's own W (the lattice-scaled W_spiky), so that
// grad C_i is the zeroth-order term Z_i of the symmetric pressure gradient (plus the walls' share
// that the velocity update adds with k_i alone, dfsph_boundary.h place 3) over rho0: shifting
// drives the packing toward Z_i = 0, where a uniform pressure exerts no force on a particle.
// Positions only: velocities are untouched, so momentum is conserved exactly.
//
// The step is clamped to kMaxStep lattice spacings a substep. At a free surface C falls and grad C
// points into the fluid, so an unrestricted shift would push the surface out: the standard rule
// keeps only the part of dr normal to the surface normal n = -grad C / |grad C| where C_i says
// surface. Here n is parallel to dr, so that part is zero: the shift fades out linearly from full
// at C_i >= kFull to none at C_i <= kNone (C_i = rho_i / rho0, the density pass's, walls
// included, so a particle at a wall is not taken for a surface).
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_base.h"
#include "host_device.h"
#include "kernels.h"
#include "neighbor_walk.h"
#include "vec3.h"

namespace sph {

struct ParticleShifting {
  float coefficient;  // C in dr = -C h^2 grad C_i
  float max_step;     // the largest |dr| a substep, in lattice spacings
  float full;         // the fill q_i at and above which the whole shift applies
  float none;         // q_i at and below which none does
  float wall_weight;  // the share of grad rho_b / rho0 in grad C_i
};

// sum_j m grad W_ij (W the pressure force's W_spiky) and sum_j W_ij, for particle i.
struct ZerothMoment {
  Vec3 gradient;
  float kernel_sum;
};
SPH_HD ZerothMoment gather_zeroth_moment(const FluidBase& f, const GridView& grid, const Float4* positions,
                                         uint32_t i) {
  KernelCoefficients mk = f.kernel;
  mk.spiky_grad *= f.particle_mass;
  const Vec3 xi = xyz(positions[i]);
  ZerothMoment z{Vec3{0.0f, 0.0f, 0.0f}, 0.0f};
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(positions[j]);
    const float r2 = length_squared(d);
    if (r2 < f.kernel.h2 && j != i) {
      const float r = square_root(r2);
      z.gradient += spiky_gradient(mk, d, r);
      z.kernel_sum += spiky_value(f.kernel, r);
    }
  });
  return z;
}

// The shift from Z_i, the walls' gradient grad rho_b(x_i) (zero without them) and the fill
// q_i = N_i / N0 + rho_b / rho0 (the neighbour count against a uniform packing's, plus the walls'
// share: about 1 in the bulk and at a wall, below 1 near a free surface); spacing: the lattice spacing.
SPH_HD Vec3 shift_displacement(const FluidBase& f, const ParticleShifting& s, Vec3 zeroth, Vec3 wall_gradient,
                               float fill, float spacing) {
  float w = (fill - s.none) / (s.full - s.none);
  w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
  if (w <= 0.0f) return Vec3{0.0f, 0.0f, 0.0f};
  const Vec3 grad_c = (zeroth + wall_gradient * s.wall_weight) * (1.0f / f.rest_density);
  Vec3 dr = grad_c * (-s.coefficient * f.kernel.h2 * w);
  const float limit = s.max_step * spacing;
  const float len2 = length_squared(dr);
  if (len2 > limit * limit) dr = dr * (limit / square_root(len2));
  return dr;
}

}  // namespace sph
