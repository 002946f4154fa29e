// SPDX-License-Identifier: MIT
// Divergence-free SPH (Bender & Koschier 2015, "Divergence-free smoothed particle
// hydrodynamics"; 2017, "Divergence-Free SPH for Incompressible and Viscous Fluids"), the
// incompressible solver a world chooses instead of the thesis's weakly compressible scheme
// (sph_world_def.solver = SPH_SOLVER_DFSPH; sph_dfsph_params). Its per-particle passes are
// dfsph_passes.h; the order of a substep is each backend's (src/cpu/cpu_dfsph_solver.cpp,
// cuda/dfsph_solver.cu), written as Bender & Koschier's Algorithm 1:
//   1. density rho_i = m (w0 + sum_j W_ij) (density.h) and the factor
//      alpha_i = rho_i / (|sum_j m grad W_ij|^2 + sum_j |m grad W_ij|^2);
//   2. the divergence solve: iterate D rho_i / Dt = sum_j m (v_i - v_j) . grad W_ij (clamped
//      at 0, and 0 for a particle with too few neighbours), k_i = (D rho_i / Dt) alpha_i /
//      (dt rho_i), v_i -= dt sum_j m (k_i + k_j) grad W_ij, until the mean of
//      (D rho / Dt) / rho0 is below max(divergence_error, divergence_error_per_step / dt) (a rate,
//      per second, or a share of rho0 a step, whichever is looser) or the cap;
//   3. v* = v + dt a with the non-pressure accelerations of the world's methods (gravity,
//      viscosity, surface tension, springs, force fields);
//   4. the density solve: rho*_i = rho_i + dt sum_j m (v*_i - v*_j) . grad W_ij,
//      k_i = max(rho*_i - rho0, 0) alpha_i / (dt^2 rho_i), v*_i -= dt sum_j m (k_i + k_j)
//      grad W_ij, until the mean of max(rho* - rho0, 0) / rho0 is below density_error and the
//      largest below density_error_max, with at least two iterations, or the cap;
//   5. x += dt v*, then the colliders, sinks and the max-speed reduction for the next step.
// k = kappa / rho = p / rho^2 (the symmetric pressure force of pressure_force.h with
// p_i = kappa_i rho_i), so the passes read one float per neighbour and no density. The kernel
// is the world's lattice-scaled W_spiky, the density's own, so the discrete divergence and
// gradient are those of the density sum (the energy argument of density.h holds).
//
// Warm starts: each solve starts from half the pressure it ended the previous substep with (the
// reference implementation's choice: the solves only ever add pressure, so a stale pressure
// that a full warm start re-applied could never be taken back; halved, it fades within a few
// substeps unless the solve renews it). The carried values are made independent of the step:
// the density solve's p / rho^2 is a pressure, the same whatever dt; the divergence solve's is
// an impulse, carried times dt.
//
// Not used by DFSPH: the equation of state (its stiffness and Tait's speed of sound) and the
// acoustic step limit; the step is dt = step_factor h / v_max (a CFL number on the particle
// speed), clamped by dt_max, by the viscous, spring and force limits of the methods, and by the
// depth limit f h / sqrt(|g| H) (depth_step_factor; step_control.h), which still water needs.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "param_table.h"
#include "particle_array_spec.h"
#include "world_shape.h"

namespace sph {

// sph_dfsph_params.flags (SPH_DFSPH_*).
enum DfsphFlags : uint32_t {
  kDfsphSkipDivergenceSolve = 1u << 0,
  kDfsphCorrectedGradient = 1u << 1,  // dfsph_gradient_correction.h
  kDfsphNoDepthStepLimit = 1u << 2,   // the depth step limit off (step_control.h)
  kDfsphFlagsAll = 7u
};
// sph_dfsph_params.linear_solver (SPH_DFSPH_JACOBI, SPH_DFSPH_CONJUGATE_GRADIENTS,
// SPH_DFSPH_CHEBYSHEV): how the density solve iterates (dfsph_cg.h has the conjugate gradients'
// method, dfsph_chebyshev.h the Chebyshev steps').
enum DfsphLinearSolver : uint32_t { kDfsphJacobi = 1, kDfsphConjugateGradients = 2, kDfsphChebyshev = 3 };

// The names of DFSPH's per-particle arrays.
constexpr const char* kArrayDfsphPressure = "dfsph_pressure";              // p / rho^2 of the density solve
constexpr const char* kArrayDfsphDivergencePressure = "dfsph_divergence";  // p_v / rho^2 times dt
constexpr const char* kArrayDfsphFactor = "dfsph_factor";                  // alpha_i / rho_i
constexpr const char* kArrayDfsphStep = "dfsph_step";                      // this iteration's k_i
constexpr const char* kArrayDfsphResidual = "dfsph_residual";              // the particle's error
constexpr const char* kArrayDfsphWarmPressure = "dfsph_warm_pressure";     // warm start, sorted order
constexpr const char* kArrayDfsphContact = "dfsph_contact";                // Float4: wall normal, speed
// The conjugate gradients' density solve (dfsph_cg.h; registered by particle_arrays.cpp only where
// it may run): rho* - rho0, its change along the search direction, the search direction's
// velocity change, and the particle's flags (in the active set, contact binds).
constexpr const char* kArrayDfsphCgValue = "dfsph_cg_value";
constexpr const char* kArrayDfsphCgChange = "dfsph_cg_change";
constexpr const char* kArrayDfsphCgVelocityStep = "dfsph_cg_velocity_step";  // Float4
constexpr const char* kArrayDfsphCgState = "dfsph_cg_state";                 // uint8_t

struct Dfsph {
  static constexpr const char* kName = "dfsph";

  struct Params {
    float density_error = 0.001f;  // bound on the mean max(rho* - rho0, 0) / rho0
    // Bound on the largest max(rho* - rho0, 0) / rho0 of any particle. The mean alone lets a small
    // violent region (a splash at a wall) stay compressed by 50-100 % in a large calm world, whose
    // mean it barely moves, and such a world threw its water (docs/physics.md, DFSPH limits).
    float density_error_max = 0.05f;
    float divergence_error = 1.0f;  // bound on the mean max(D rho / Dt, 0) / rho0, 1/s
    // The same bound as a share of rho0 a step (the mean rate times dt): the solve stops at the
    // looser of the two. A fixed rate alone grows stricter as the step shrinks (0.01 % a step at the
    // million-particle dam break's 0.1 ms), and the divergence solve then spent more passes than the
    // density solve (docs/validation.md, "Session 30: the divergence bound is a fixed rate");
    // SPlisHSPlasH bounds it at 0.1 % a step. At the defaults the rate governs steps above 1 ms
    // (possible only with dt_max raised above its default, 1 ms).
    float divergence_error_per_step = 0.001f;
    uint32_t max_iterations = 100;  // of the density solve, per substep
    uint32_t max_divergence_iterations = 100;
    uint32_t flags = 0;                     // DfsphFlags
    uint32_t linear_solver = kDfsphJacobi;  // DfsphLinearSolver
    // f of the depth step limit dt <= f h / sqrt(|g| H) (step_control.h): 17 % under the largest
    // ratio at which every measured tank settled (0.36; all blew at 0.39).
    float depth_step_factor = 0.3f;
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("density_error", &Params::density_error, above_up_to(0.0, 1.0), ZeroMeans::Default, ""),
      real_field("divergence_error", &Params::divergence_error, above(0.0), ZeroMeans::Default, "1/s"),
      count_field("max_iterations", &Params::max_iterations, at_least(2.0), ZeroMeans::Default),
      count_field("max_divergence_iterations", &Params::max_divergence_iterations, at_least(1.0),
                  ZeroMeans::Default),
      bits_field("flags", &Params::flags, kDfsphFlagsAll),
      count_field("linear_solver", &Params::linear_solver, within(1.0, 3.0), ZeroMeans::Default),
      real_field("density_error_max", &Params::density_error_max, above_up_to(0.0, 1.0), ZeroMeans::Default,
                 ""),
      real_field("depth_step_factor", &Params::depth_step_factor, above_up_to(0.0, 1.0), ZeroMeans::Default,
                 ""),
      real_field("divergence_error_per_step", &Params::divergence_error_per_step, above_up_to(0.0, 1.0),
                 ZeroMeans::Default, ""),
  };
  // The corrected gradient is the plain Jacobi solve's (dfsph_gradient_correction.h): its operator is
  // not the symmetric one the conjugate gradients' density solve needs (dfsph_cg.h), and with the
  // Chebyshev solve a fluid started compressed against the walls went non-finite in its fifth substep
  // (physics_dfsph_extremes_corrected_wall's start, which the plain solve runs; docs/physics.md).
  static bool check(const Params& p, const WorldShape&, ParamConflict& out) {
    if ((p.flags & kDfsphCorrectedGradient) && p.linear_solver != kDfsphJacobi) {
      out = ParamConflict{"flags", static_cast<float>(p.flags),
                          "(SPH_DFSPH_CORRECTED_GRADIENT) works with SPH_DFSPH_JACOBI only, not",
                          "linear_solver", static_cast<float>(p.linear_solver)};
      return false;
    }
    return true;
  }

  // The density solve runs at least this many iterations (the reference's minimum: a first
  // iteration alone, from a warm start, can stop on an error it has not looked at since).
  static constexpr uint32_t kMinIterations = 2;
  static constexpr uint32_t kMinDivergenceIterations = 1;
  // The share of the last substep's pressure a solve starts from (see above).
  static constexpr float kWarmStart = 0.5f;
  // The conjugate gradients' density solve (dfsph_cg.h) starts a new cycle when the compression
  // outside its active set reaches this share of the bound.
  static constexpr float kCgRestartShare = 0.5f;
  // A particle with fewer neighbours than this share of the full lattice's (42 at h = 1.8
  // spacings) gets no divergence correction: at a free surface or a splash the divergence of
  // a half-empty neighbourhood is not the fluid's (the reference uses 20 of about 45).
  static constexpr float kDivergenceNeighborShare = 0.45f;
  // alpha_i is 0 (no pressure) where its denominator is below this share of one pair's largest
  // term (m |grad W(0)|)^2: an isolated particle, whose alpha would be infinite.
  static constexpr float kFactorFloor = 1e-6f;

  struct Constants {
    float density_error;
    float density_error_max;  // never below density_error
    float divergence_error;   // 1/s
    float divergence_error_per_step;
    uint32_t max_iterations;
    uint32_t max_divergence_iterations;
    uint32_t divergence_solve;  // 1 unless kDfsphSkipDivergenceSolve
    uint32_t min_divergence_neighbors;
    uint32_t linear_solver;        // DfsphLinearSolver
    uint32_t gradient_correction;  // 1: the Jacobi solves' corrected gradient (dfsph_gradient_correction.h)
  };
  static Constants make_constants(const Params& p, const WorldShape& shape, const LatticeSums& lattice) {
    Constants c;
    c.density_error = p.density_error;
    c.density_error_max = p.density_error_max > p.density_error ? p.density_error_max : p.density_error;
    c.divergence_error = p.divergence_error;
    c.divergence_error_per_step = p.divergence_error_per_step;
    c.max_iterations = p.max_iterations < kMinIterations ? kMinIterations : p.max_iterations;
    c.max_divergence_iterations = p.max_divergence_iterations < kMinDivergenceIterations
                                      ? kMinDivergenceIterations
                                      : p.max_divergence_iterations;
    c.divergence_solve = (p.flags & kDfsphSkipDivergenceSolve) ? 0u : 1u;
    const double full =
        static_cast<double>(lattice.neighbor_count(shape.particle_spacing, shape.kernel_radius));
    c.min_divergence_neighbors = static_cast<uint32_t>(kDivergenceNeighborShare * full + 0.5);
    c.linear_solver = p.linear_solver;
    c.gradient_correction = (p.flags & kDfsphCorrectedGradient) ? 1u : 0u;
    return c;
  }

  // Carried: the two solves' pressures (warm starts; sorted, rolled back, saved). Scratch: the
  // factor, the pressure of the iteration that neighbours read (and, SPH_DFSPH_CHEBYSHEV, the step
  // its next residual pass mixes in), each particle's error for the solve's mean (CPU), the density solve's
  // warm start gathered into the sorted order (CUDA), the particle's contact with the colliders
  // (dfsph_passes.h, wall_contact), and the density pass's neighbour counts (the divergence solve skips
  // particles with too few).
  static constexpr ParticleArraySpec kArrays[] = {
      {kArrayDfsphPressure, sizeof(float), ParticleArrayRole::Carried, 1, nullptr, nullptr},
      {kArrayDfsphDivergencePressure, sizeof(float), ParticleArrayRole::Carried, 1, nullptr, nullptr},
      {kArrayDfsphFactor, sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
      {kArrayDfsphStep, sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
      {kArrayDfsphResidual, sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
      {kArrayDfsphWarmPressure, sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
      {kArrayDfsphContact, 4 * sizeof(float), ParticleArrayRole::Scratch, 1, nullptr, nullptr},
      {kArrayNeighborCount, sizeof(uint32_t), ParticleArrayRole::Scratch, 1, nullptr, nullptr}};
};

// A solve's measured error: the mean over the particles, and the largest of one particle.
struct DfsphErrors {
  float mean;
  float largest;
};
// The solves' bounds, on both backends: the mean error's, and (the density solve, Jacobi or
// conjugate gradients alike) the largest particle error's. A solve goes on while one is unmet (or its minimum
// has not run) and below its cap; one that stops with a bound unmet is capped. The divergence solve bounds
// only its mean, at the looser of its rate and its share a step over the substep's dt.
struct DfsphBounds {
  float mean;
  float largest;
};
constexpr float kDfsphNoBound = 3.0e38f;
SPH_HD bool dfsph_bounds_unmet(const DfsphBounds& b, const DfsphErrors& e) {
  return e.mean > b.mean || e.largest > b.largest;
}
SPH_HD DfsphBounds dfsph_density_bounds(const Dfsph::Constants& c) {
  return {c.density_error, c.density_error_max};
}
// IEEE division on both backends: a distributed CUDA rank decides on the host what an undivided
// world's check kernel decides on the device (the same bits, gpu_check_mpi).
SPH_HD DfsphBounds dfsph_divergence_bounds(const Dfsph::Constants& c, float dt) {
  const float per_step = ieee_divide(c.divergence_error_per_step, dt);
  return {per_step > c.divergence_error ? per_step : c.divergence_error, kDfsphNoBound};
}
// The bounds of the divergence solve (divergence) or of the density solve (which does not read dt).
SPH_HD DfsphBounds dfsph_solve_bounds(const Dfsph::Constants& c, bool divergence, float dt) {
  return divergence ? dfsph_divergence_bounds(c, dt) : dfsph_density_bounds(c);
}

}  // namespace sph
