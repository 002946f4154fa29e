// SPDX-License-Identifier: MIT
// DFSPH's Jacobi solve as the host drives it, one iteration at a time, written once for the CPU
// backend (src/cpu/cpu_dfsph_solver.cpp, undivided or a rank) and a distributed CUDA rank
// (cuda/dfsph_jacobi_rank_solver.cu; an undivided CUDA world runs the same loop on the device,
// cuda/dfsph_solve_loop.cuh, by the same stopping rule). In a distributed world this is where
// the ghosts are refreshed between the passes (docs/distributed.md): each velocity update is
// followed by the ghosts taking their owners' velocities (the rate pass reads its neighbours'),
// each rate pass by their taking their owners' pressure steps k (the next velocity update reads
// them), and the errors are the world's (the mean: each rank's exact sum, its bins added over the
// ranks; the largest: the ranks' largest), so every rank takes the same decision as the undivided
// world. Undivided, the shares do nothing.
#pragma once

#include <stdint.h>

#include "../physics/dfsph.h"
#include "../physics/host_device.h"

namespace sph {

// The stopping rule, after the initial residual (iterations 0) and after each iteration: on while
// a bound is unmet (physics/dfsph.h) or the minimum has not run, and below the cap.
SPH_HD bool dfsph_solve_goes_on(const DfsphErrors& errors, uint32_t iterations, const DfsphBounds& bounds,
                                uint32_t min_iterations, uint32_t max_iterations) {
  return (dfsph_bounds_unmet(bounds, errors) || iterations < min_iterations) && iterations < max_iterations;
}

struct DfsphLoopOutcome {
  uint32_t iterations;  // after the initial residual
  DfsphErrors errors;   // the mean and largest error the solve ended with
  bool capped;          // stopped at the cap with a bound unmet
};

// Runs the solve on `passes`, which provides (each on the rank's own particles and its ghosts):
//   void velocity_update(bool warm)  v += the velocity change of the pressure steps k (warm: the
//                                    warm start's steps, the first update of the solve)
//   void share_velocities()          a rank's ghosts take their owners' velocities
//   void rates()                     each particle's rate of density change, new k and error
//   void share_steps()               a rank's ghosts take their owners' k
//   DfsphErrors errors()             the mean and largest error over the world's particles (ghosts
//                                    left out)
//   void checked(uint32_t iterations, const DfsphErrors& errors, bool goes_on)   after each test
template <class Passes>
DfsphLoopOutcome run_dfsph_jacobi(Passes& passes, const DfsphBounds& bounds, uint32_t min_iterations,
                                  uint32_t max_iterations) {
  auto iteration = [&](bool warm) {
    passes.velocity_update(warm);
    passes.share_velocities();  // the next rate pass reads the ghosts' velocities
    passes.rates();
    passes.share_steps();  // the next velocity update reads the ghosts' k
    return passes.errors();
  };
  DfsphErrors errors = iteration(true);
  uint32_t iterations = 0;
  bool more = dfsph_solve_goes_on(errors, iterations, bounds, min_iterations, max_iterations);
  passes.checked(iterations, errors, more);
  while (more) {
    errors = iteration(false);
    ++iterations;
    more = dfsph_solve_goes_on(errors, iterations, bounds, min_iterations, max_iterations);
    passes.checked(iterations, errors, more);
  }
  return DfsphLoopOutcome{iterations, errors, dfsph_bounds_unmet(bounds, errors)};
}

}  // namespace sph
