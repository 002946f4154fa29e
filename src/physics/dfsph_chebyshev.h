// SPDX-License-Identifier: MIT
// DFSPH's Chebyshev density solve (SPH_DFSPH_CHEBYSHEV), written once for both backends: its
// weights, its release of expanded particles' pressure, its guard, and one particle's residual
// pass, on dfsph_passes.h's plain density step (density_residual).
#pragma once

#include <stdint.h>

#include "dfsph_passes.h"

namespace sph {

// SPH_DFSPH_CHEBYSHEV: the density solve's Jacobi steps accelerated by Chebyshev's semi-iteration
// (Golub & Varga 1961; as Wang 2015 does for position-based dynamics). The plain solve's steps
// converge at the rate rho of the Jacobi iteration, and rho approaches 1 as a world grows, so its
// iterations grow with the resolution (4.7 a substep at 20 layers of the dam break, 13.7 at 80).
// The semi-iteration mixes each Jacobi step with the step before it,
//     k_n = w_n k_jacobi + (w_n - 1) k_(n-1),   w_0 = 1, w_1 = 2 / (2 - rho^2),
//     w_(n+1) = 4 / (4 - rho^2 w_n),
// which converges at about (1 - sqrt(1 - rho^2)) / rho (the Chebyshev polynomial's rate) for the
// same two neighbour passes an iteration. Two things make it safe for the density solve:
// - the plain steps are never negative (only compression is corrected), so an accelerated step
//   that pushes too hard could not be taken back: the expanded particles it leaves are no error to
//   the solve, and their pressure does work (the closed box gained 39-fold its energy once settled).
//   So a particle whose rho* is at or below rho0 takes a negative step, kRelease of the plain
//   formula's, never more than the pressure it holds (the solve's pressure stays >= 0);
// - kRelease is small because Jacobi's full step on the two-sided problem oscillates (the release
//   at 1 grew a particle's pressure and its release by about 20 % an iteration until the step
//   failed).
// The errors and the stopping rule are the plain solve's (only compression counts).
struct DfsphChebyshev {
  // The spectral radius the weights assume. Measured on the dam break (bench/solver_front, 0.1 %;
  // docs/physics.md): 0.95 took 4-5 % fewer passes than 0.9 at 40-120 layers, but at 160 layers
  // a solve capped where the front meets the wall and the divergence solve took 5.7 iterations a
  // substep (0.9: none capped, 3.4, and 3.5 % fewer passes), and at 1M particles on the GPU 0.95
  // went unstable there (session 29). So 0.9: robustness over the last few percent.
  static constexpr float kSpectralRadius = 0.9f;
  // The share of the plain step an expanded particle releases (0.5 and 0.25 measured; 0.25 kept).
  static constexpr float kRelease = 0.25f;
  // The guard (DfsphChebyshevGuard below): a solve whose mean error passes this many times the
  // smallest it reached, and its own bound, takes plain steps from then on.
  static constexpr float kGuardGrowth = 2.0f;
};

// Whether a solve is SPH_DFSPH_CHEBYSHEV's accelerated density solve: the one whose residual pass
// mixes its steps (chebyshev_density_residual) and whose guard is kept and counted. The divergence
// solve, and the density solve of the other linear solvers, take the plain steps.
SPH_HD bool chebyshev_density_solve(const Dfsph::Constants& c, bool divergence) {
  return !divergence && c.linear_solver == kDfsphChebyshev;
}

// The Chebyshev solve's guard. The weights assume the Jacobi iteration's spectral radius is at most
// kSpectralRadius; where a world's is not (measured in session 40: kernel radii of 2.2 to 3
// spacings, whose larger neighbourhoods the weights were not fitted to, in dam breaks of 3,000 to
// 25,000 particles on the CPU), the semi-iteration grows the error 1.3-1.7 times an iteration
// until the cap, and the step fails with non-finite velocities, where the plain solve converges.
// The release is part of it: with weight 1 and the release a kernel of 3 spacings still diverged
// (3.4 times an iteration), the plain solve's own steps (never negative) did not. So once a
// solve's mean error passes kGuardGrowth times the smallest it reached and the solve's own bound,
// the rest of that solve takes the plain solve's step (density_residual: weight 1, no release); the
// next solve starts accelerated again. A solve whose error stays within its bound, or falls, is
// never touched (session 28: a restart at a doubling never fired at the spectral radius 0.95 on the
// dam break), so where the guard does not fire the accelerated solve keeps its bits. Both backends
// keep it after each test of the solve (the CPU's loop, the CUDA check kernels), on the world's
// mean error.
struct DfsphChebyshevGuard {
  float smallest = 0.0f;  // the solve's smallest mean error so far
  uint32_t plain = 0u;    // nonzero: the rest of the solve takes weight 1
};

// After the solve's test number `iterations` (0: the first, after the warm start) read `mean`;
// `bound` the solve's bound on it. Only a mean above the bound arms it: below, the solve may stop
// any time, and rounding-level errors (a resting world's 0 or 1e-9 moving to 4e-9, measured in the
// 3-spacing case's first frames) or a solve kept going by its largest-error bound are not a
// divergence; a divergence passes the bound within an iteration or two.
SPH_HD void chebyshev_guard_check(DfsphChebyshevGuard& guard, uint32_t iterations, float mean, float bound) {
  if (iterations == 0u) {
    guard.smallest = mean;
    guard.plain = 0u;
    return;
  }
  if (mean > DfsphChebyshev::kGuardGrowth * guard.smallest && mean > bound) guard.plain = 1u;
  if (mean < guard.smallest) guard.smallest = mean;
}

// w_n of the residual pass n of a solve (0: the first, after the warm start). The recurrence
// reaches its fixed point in floats within a few dozen steps (it contracts by about a half a
// step), where the loop stops: a cap of a million iterations costs no more than one of a hundred.
SPH_HD float chebyshev_weight(uint32_t n) {
  const float r2 = DfsphChebyshev::kSpectralRadius * DfsphChebyshev::kSpectralRadius;
  if (n == 0) return 1.0f;
  float w = 2.0f / (2.0f - r2);
  for (uint32_t m = 2; m <= n; ++m) {
    const float next = 4.0f / (4.0f - r2 * w);
    if (next == w) break;
    w = next;
  }
  return w;
}

// What residual pass n of the Chebyshev solve applies under the guard: its weight
// (chebyshev_weight(n)), or, once the guard holds, the plain solve's step.
struct DfsphChebyshevPass {
  float weight;
  uint32_t plain;  // nonzero: density_residual's step (weight 1)
};
SPH_HD DfsphChebyshevPass chebyshev_guarded_pass(const DfsphChebyshevGuard& guard, uint32_t n) {
  return DfsphChebyshevPass{guard.plain ? 1.0f : chebyshev_weight(n), guard.plain};
}

// The density solve's residual with the release: density_residual's where rho* > rho0; elsewhere a
// negative step, kRelease of the same formula, limited to the pressure `held` (the solve's pressure
// so far, warm start included; >= 0). error as density_residual's.
SPH_HD DfsphResidual density_residual_released(float rate, float density, float factor, float rest_density,
                                               float dt, float held) {
  const float predicted = density + dt * rate;
  if (predicted > rest_density) return density_residual(rate, density, factor, rest_density, dt);
  const float k = DfsphChebyshev::kRelease * (predicted - rest_density) * factor / (dt * dt);
  return DfsphResidual{k < -held ? -held : k, 0.0f};
}

// The step the Chebyshev solve applies from the pass's Jacobi step and the step applied before it,
// with the pass's weight (chebyshev_weight; at w = 1, the first pass, the Jacobi step alone, the
// previous step not read), limited as the release is.
SPH_HD float chebyshev_step(float weight, float jacobi_step, float previous_step, float held) {
  if (weight == 1.0f) return jacobi_step;
  const float k = weight * jacobi_step + (weight - 1.0f) * previous_step;
  return k < -held ? -held : k;
}

// One particle's residual pass of the Chebyshev density solve, as both backends run it: the released
// residual mixed with `previous`, the step the particle applied in the pass before (read only past the
// first pass, weight != 1: before it the array holds no residual step of this solve). Both backends pass the
// particle's own slot of the steps' array (dfsph_step), which still holds that step: the velocity
// update between two residual passes only reads it, and a rank's ghosts take their owners' steps,
// which only ghosts' own (discarded) residuals read. k: the step to apply (it overwrites `previous`
// in the caller); error: the plain solve's.
SPH_HD DfsphResidual chebyshev_density_residual(float rate, float density, float factor, float rest_density,
                                                float dt, float held, DfsphChebyshevPass pass,
                                                const float* previous) {
  if (pass.plain) return density_residual(rate, density, factor, rest_density, dt);  // (the guard's)
  const float weight = pass.weight;
  const DfsphResidual r = density_residual_released(rate, density, factor, rest_density, dt, held);
  return DfsphResidual{chebyshev_step(weight, r.k, weight == 1.0f ? 0.0f : *previous, held), r.error};
}

}  // namespace sph
