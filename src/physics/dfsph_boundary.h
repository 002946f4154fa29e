// The walls' share in DFSPH's sums: where a boundary model (colliders' SDFs as boundary volume or
// density maps, issue 16 item 2, the `boundary` module) enters the incompressible solver. DFSPH
// takes it at exactly three places, each a single call of wall_share() below:
//   1. the density and factor pass (dfsph_passes.h, gather_density_and_factor):
//      rho_i += rho_b(x_i), and grad rho_b(x_i) joins sum_j m grad W_ij in alpha's denominator;
//   2. both solves' density rate (density_rate): D rho_i / Dt += (v_i - v_b) . grad rho_b(x_i),
//      v_b the wall's velocity at x_i (a moving collider's; zero for a static one);
//   3. both solves' velocity update (pressure_velocity_change): the wall's share with k_i alone,
//      v_i -= dt k_i grad rho_b(x_i) (the wall does not move in response).
// rho_b(x) = sum over the wall's volume of m W(x - x_b) (a density map, Koschier & Bender 2017;
// a volume map, Bender et al. 2019, gives it as rho0 V_b W(x - x_b) and its gradient), in the
// world's lattice-scaled W_spiky so that a fluid lattice resting on a wall reads rho0.
//
// Until that module is connected this is a stub: no wall contributes, and DFSPH sees walls only
// through the collision response (particles at a wall read a low density, as the weakly
// compressible scheme's do). The backends build a DfsphWalls per substep and hand it to the
// passes by value; the boundary module fills it (collider views, their maps, the substep's time).
#pragma once

#include "host_device.h"
#include "vec3.h"

namespace sph {

// What the passes need to sample the walls (empty while no boundary model is connected).
struct DfsphWalls {};

struct WallShare {
  float density;  // rho_b(x), kg/m^3
  Vec3 gradient;  // grad rho_b(x), kg/m^4: the walls' sum_b m grad W(x - x_b)
  Vec3 velocity;  // the walls' velocity at x, m/s
};

SPH_HD WallShare wall_share(const DfsphWalls&, Vec3) {
  return WallShare{0.0f, Vec3{0.0f, 0.0f, 0.0f}, Vec3{0.0f, 0.0f, 0.0f}};
}

}  // namespace sph
