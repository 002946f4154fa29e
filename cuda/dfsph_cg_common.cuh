// SPDX-License-Identifier: MIT
// What DFSPH's two device solves by conjugate gradients share: the undivided world's
// (dfsph_cg_solver.cu, the device drives the loop) and a distributed rank's
// (dfsph_cg_rank_solver.cu, the host drives it as the CPU rank's loop). The arguments every
// kernel reads, each particle's share of a step (one text for both solves: the same terms, the
// same bits), and the undivided solve's particle kernels without sums, which the rank's solve
// launches too (defined in dfsph_cg_solver.cu; a launch from another file needs only the host
// stub, no separate device compilation).
#pragma once

#include <stdint.h>

#include "../src/physics/dfsph_cg.h"
#include "../src/physics/dfsph_passes.h"
#include "dfsph_solve_loop.cuh"
#include "dfsph_solver.h"

namespace sph {

// ParticleArrays::dfsph_cg_state's bits: in the cycle's set; its contact binds.
constexpr uint8_t kCgActive = 1, kCgBinds = 2;

// What every kernel of the solve reads.
struct CgSolve {
  FluidConstants fluid;
  GridView grid;
  ParticleArrays a;
  uint32_t n;
  bool contacts;
  uint32_t blocks;  // of kDfsphSolveBlock threads: partials [0, blocks) and [blocks, 2 blocks)
  LoopCondition cond;
  FrameState* state;
  double* partials;
};

__device__ inline DfsphWalls cg_walls(const CgSolve& s) { return DfsphWalls{s.a.boundary_gradient}; }

// The neighbours of particle i, through the density pass's neighbour lists or candidate masks
// (every candidate where the world has neither).
__device__ inline ListedCandidates cg_walk(const CgSolve& s) { return solve_walk(s.a); }

// A particle's term of a sum over the cycle's set, and whether it is in the set.
struct CgTerm {
  float value;
  bool active;
};

// After the warm start: particle i's value rho* - rho0 over the velocities (stored); its error.
__device__ inline float cg_measure_particle(const CgSolve& s, uint32_t i) {
  const float dt = s.state->clock.dt_float;
  const float rate =
      density_rate(s.fluid, s.grid, s.a.sorted_position, s.a.velocity, cg_walls(s), i, cg_walk(s));
  const float value = dfsph_cg_value(rate, s.a.density[i], s.fluid.rest_density, dt);
  s.a.dfsph_cg_value[i] = value;
  return dfsph_cg_error(value, s.fluid.rest_density);
}

// A new cycle at particle i: its set and binding contact, its steepest (preconditioned) direction
// p; the term value . p.
__device__ inline CgTerm cg_restart_particle(const CgSolve& s, uint32_t i) {
  const float dt = s.state->clock.dt_float;
  const float value = s.a.dfsph_cg_value[i], factor = s.a.dfsph_factor[i];
  const bool active = dfsph_cg_active(value, s.a.dfsph_pressure[i], factor);
  const bool binds = s.contacts && dfsph_contact_binds(s.a.dfsph_contact[i], xyz(s.a.velocity[i]));
  s.a.dfsph_cg_state[i] = static_cast<uint8_t>((active ? kCgActive : 0) | (binds ? kCgBinds : 0));
  const float p = active ? dfsph_cg_step(value, factor, dt) : 0.0f;
  s.a.dfsph_step[i] = p;
  return CgTerm{value * p, active};
}

// The operator on p, second half: the change of particle i's value from the rates of dv_p alone
// (stored); the term p . A p (-p . change).
__device__ inline CgTerm cg_change_particle(const CgSolve& s, uint32_t i) {
  const float dt = s.state->clock.dt_float;
  const DfsphWalls walls = cg_walls(s);
  const float rate =
      density_rate(s.fluid, s.grid, s.a.sorted_position, s.a.dfsph_cg_velocity_step, walls, i, cg_walk(s));
  const float change = dfsph_cg_change(rate, walls, i, dt);
  s.a.dfsph_cg_change[i] = change;
  return CgTerm{-s.a.dfsph_step[i] * change, (s.a.dfsph_cg_state[i] & kCgActive) != 0};
}

// Particle i's value after an update: with contacts held in it, their changes added (the rate of
// the held changes: m (dv_i - dv_j) . grad W_ij and dv_i . grad rho_b, what the CPU's walks add).
__device__ inline float cg_held_value(const CgSolve& s, uint32_t i) {
  float value = s.a.dfsph_cg_value[i];
  if (s.contacts && s.state->cg_held) {
    const float dt = s.state->clock.dt_float;
    const DfsphWalls walls = cg_walls(s);
    const float rate =
        density_rate(s.fluid, s.grid, s.a.sorted_position, s.a.dfsph_cg_velocity_step, walls, i, cg_walk(s));
    value += dfsph_cg_change(rate, walls, i, dt);
    s.a.dfsph_cg_value[i] = value;
  }
  return value;
}

// Particle i's Jacobi step z over the set (the preconditioned residual, stored) from its value;
// the term value . z.
__device__ inline CgTerm cg_residual_particle(const CgSolve& s, uint32_t i, float value) {
  const bool active = (s.a.dfsph_cg_state[i] & kCgActive) != 0;
  const float z = active ? dfsph_cg_step(value, s.a.dfsph_factor[i], s.state->clock.dt_float) : 0.0f;
  s.a.dfsph_residual[i] = z;
  return CgTerm{value * z, active};
}

// The operator on p, first half, at particle i: the velocities p would give (a binding contact's
// normal part removed), stored. (The conjugate gradients refuse the corrected gradient: the operator
// must be symmetric.)
__device__ inline void cg_direction_particle(const CgSolve& s, uint32_t i) {
  const float dt = s.state->clock.dt_float;
  Vec3 d = pressure_velocity_change<false>(s.fluid, s.grid, s.a.sorted_position, s.a.dfsph_step, cg_walls(s),
                                           i, dt, cg_walk(s));
  if (s.a.dfsph_cg_state[i] & kCgBinds) d = dfsph_contact_project(s.a.dfsph_contact[i], d);
  s.a.dfsph_cg_velocity_step[i] = make_float4_record(d, 0.0f);
}

// The undivided solve's particle kernels that the rank's solve runs too (dfsph_cg_solver.cu):
// the update by alpha, the next direction by beta (alpha, beta and the flags from the state), and
// the pressure the solve keeps. (The velocities p gives: cg_direction_particle, in a kernel of each
// solve's own, as a rank's skips its ghosts.)
__global__ void cg_update_kernel(CgSolve s);
__global__ void cg_next_direction_kernel(CgSolve s);
__global__ void cg_keep_kernel(float* pressure, uint32_t n);

}  // namespace sph
