// SPDX-License-Identifier: MIT
// DFSPH's density solve by conjugate gradients (sph_dfsph_params.linear_solver =
// SPH_DFSPH_CONJUGATE_GRADIENTS): the per-particle formulas and the restart rule, written for both
// backends (src/cpu/cpu_dfsph_cg.cpp, cuda/dfsph_cg_solver.cu). The divergence solve stays a Jacobi iteration
// (measured: conjugate gradients took more of its iterations; docs/validation.md, "DFSPH by conjugate
// gradients").
//
// Why it is a symmetric system: with equal masses the velocity update is dv = -dt G k,
// (G k)_i = sum_j m (k_i + k_j) grad W_ij + k_i grad rho_b, and the density rate is
// (D v)_i = sum_j m (v_i - v_j) . grad W_ij + v_i . grad rho_b; swapping i and j in the double
// sums gives <k, D v> = <G k, v>, so D = G^T, and a pressure k changes the predicted density
// rho* = rho + dt D v by -dt^2 G^T G k: a symmetric positive semidefinite operator whose diagonal
// is the DFSPH factor's denominator, 1 / (alpha_i / rho_i). The Jacobi solve is the diagonal step
// of it and removes a smooth, column-scale error at a rate that falls as 1 / layers^2; conjugate
// gradients (preconditioned by the same diagonal) at about 1 / layers.
//
// The clamp (pressure only where the fluid is compressed) makes it a bound-constrained problem.
// The solve works on an active set taken when a cycle starts: the particles that are compressed
// (value rho* - rho0 > 0) or carry pressure from this substep (which the solve may then lower),
// with a factor. The search direction is 0 outside it; every particle's value is tracked (it is
// affine in v), so the solve's error counts all particles. A cycle restarts (steepest descent
// from the current state, the set taken anew) when the compression outside its set reaches
// kCgRestartShare of the mean bound or one particle outside it is above the largest bound
// (dfsph_cg_restart_due). A particle's pressure may fall below 0 within a substep (the
// velocities keep what it applied); the solve keeps its positive part (dfsph_cg_kept_pressure).
//
// Each iteration is one velocity update with the search direction p as k (dv_p = -dt G p) and one
// rate pass over dv_p alone (dfsph_cg_change): change = -dt^2 A p, so
// alpha = (value . z) / (p . (-change)) over the set, z the Jacobi step (the preconditioned
// residual); then v += alpha dv_p, value += alpha change, the carried pressure += alpha p. Two
// neighbour passes, as a Jacobi iteration, and three exact sums.
//
// The contacts (dfsph_passes.h, respect_contact) are not linear. A particle whose contact binds
// when a cycle starts, or that an iteration held to its contact, moves only along its wall for
// the rest of the solve (dv's normal part removed: a linear projection, so the operator stays
// symmetric). Each iteration holds every velocity to its contact as the Jacobi solve does and
// adds the change to the tracked values of the particle and its neighbours (one walk over the
// neighbours of each held particle, not a pass over all).
#pragma once

#include <math.h>
#include <stdint.h>

#include "dfsph.h"
#include "dfsph_boundary.h"
#include "float4_types.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

// The value the solve drives to zero at particle i: rho* - rho0, rho* = rho_i + dt D rho_i / Dt.
SPH_HD float dfsph_cg_value(float rate, float density, float rest_density, float dt) {
  return density + dt * rate - rest_density;
}

// The change of the value that a velocity change dv makes, from the rate pass over dv alone
// (rate = D dv minus the walls' constant v_b . grad rho_b, which is put back: the change is linear).
SPH_HD float dfsph_cg_change(float rate_of_dv, const DfsphWalls& walls, uint32_t i, float dt) {
  return dt * (rate_of_dv - wall_density_rate(walls, i, Vec3{0.0f, 0.0f, 0.0f}));
}

// The particle's share of the solve's mean error (as density_residual: compression only).
SPH_HD float dfsph_cg_error(float value, float rest_density) {
  return value > 0.0f ? value / rest_density : 0.0f;
}

// Whether particle i takes part in a cycle: compressed, or carrying pressure that the solve may
// lower, and with a factor (not isolated).
SPH_HD bool dfsph_cg_active(float value, float carried, float factor) {
  return (value > 0.0f || carried > 0.0f) && factor > 0.0f;
}

// The preconditioned residual z_i: the Jacobi step's k_i for the value.
SPH_HD float dfsph_cg_step(float value, float factor, float dt) { return value * factor / (dt * dt); }

// Whether the cycle must restart with a new set, from the errors of the particles outside the set
// that a new set could take (with a factor: one without, which no pressure reaches, would restart
// every cycle): their sum over all particles' count (outside_mean, a double as the backends' sums)
// at kCgRestartShare of the mean bound, or one of them above the largest bound. The mean alone let
// a particle compressed during the cycle outside the set stay above density_error_max, which no
// iteration of the cycle could lower, and the solve ran to its cap (docs/validation.md, "DFSPH by
// conjugate gradients").
SPH_HD bool dfsph_cg_restart_due(const DfsphBounds& bounds, double outside_mean, float outside_largest) {
  return outside_mean >= Dfsph::kCgRestartShare * bounds.mean || outside_largest > bounds.largest;
}
// What the solve keeps of a particle's pressure for the next warm start, the checkpoints and the
// pressure attribute: its positive part (the Jacobi solve's pressures are never negative, and a
// checkpoint with a negative one is refused as corrupt).
SPH_HD float dfsph_cg_kept_pressure(float applied) { return applied > 0.0f ? applied : 0.0f; }

// Whether a contact binds: the particle moves towards the wall at the largest speed it may
// (v . n at its bound, within the rounding of respect_contact).
SPH_HD bool dfsph_contact_binds(const Float4& contact, Vec3 v) {
  const Vec3 n = xyz(contact);
  if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return false;
  const float vn = dot(v, n);
  return vn <= contact.w + 1e-5f * (fabsf(vn) + fabsf(contact.w));
}

// A binding contact's velocity change within a cycle: its part along the wall's normal removed.
SPH_HD Vec3 dfsph_contact_project(const Float4& contact, Vec3 dv) {
  const Vec3 n = xyz(contact);
  return dv - n * dot(dv, n);
}

// Whether respect_contact would move v by more than its rounding.
SPH_HD bool dfsph_contact_moved(const Float4& contact, Vec3 v) {
  const Vec3 n = xyz(contact);
  const float vn = dot(v, n);
  return vn < contact.w - 1e-5f * (fabsf(vn) + fabsf(contact.w));
}

}  // namespace sph
