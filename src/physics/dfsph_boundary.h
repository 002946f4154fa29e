// SPDX-License-Identifier: MIT
// The walls' share in DFSPH's sums: where the boundary density (SPH_FEATURE_BOUNDARY_DENSITY,
// boundary_density.h: the colliders' solids as density maps) enters the incompressible solver.
// DFSPH takes it at exactly three places (dfsph_passes.h):
//   1. the density and factor pass (gather_density_and_factor): rho_i += rho_b(x_i), and
//      grad rho_b(x_i) joins sum_j m grad W_ij in alpha's denominator (the wall, which does not
//      move in response, adds no term of its own to the sum of squares);
//   2. both solves' density rate (density_rate): D rho_i / Dt += (v_i - v_b) . grad rho_b(x_i),
//      v_b the wall's velocity at x_i (boundary_density_rate: zero flux for a static collider);
//   3. both solves' velocity update (pressure_velocity_change): the wall's share with k_i alone,
//      v_i -= dt k_i grad rho_b(x_i) (boundary_gradient); with SPH_DFSPH_CORRECTED_GRADIENT times
//      the fluid's kept share where the correction acts (dfsph_gradient_correction.h).
// The density pass of each backend computes the share once per substep (boundary_share, at the
// substep's start), adds its density and stores its record, (grad rho_b, v_b . grad rho_b), in
// the array kArrayBoundaryGradient; the solves read the record through DfsphWalls. The walls'
// positions are those of the substep's start for every iteration, as the particles' are.
//
// Without the feature no wall contributes (DfsphWalls::records null), and DFSPH sees walls only
// through the contacts in its solves and the collision response: particles at a wall read a
// low density, as the weakly compressible scheme's do (docs/physics.md, DFSPH, measures both).
#pragma once

#include "boundary_density.h"
#include "float4_types.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

// What the solves need of the walls: the density pass's records (sorted order), or null.
struct DfsphWalls {
  const Float4* records;
};

// Place 2: the wall's share of D rho_i / Dt at velocity v_i.
SPH_HD float wall_density_rate(const DfsphWalls& walls, uint32_t i, Vec3 v) {
  return walls.records ? boundary_density_rate(walls.records[i], v) : 0.0f;
}

// Place 3: the sum the velocity update multiplies by k_i: grad rho_b(x_i).
SPH_HD Vec3 wall_pressure_gradient(const DfsphWalls& walls, uint32_t i) {
  return walls.records ? boundary_gradient(walls.records[i]) : Vec3{0.0f, 0.0f, 0.0f};
}

}  // namespace sph
