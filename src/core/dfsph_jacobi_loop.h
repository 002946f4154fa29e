// SPDX-License-Identifier: MIT
// DFSPH's Jacobi solve as the host drives it, one iteration at a time, written once for the CPU
// backend (src/cpu/cpu_dfsph_solver.cpp, undivided or a rank) and a distributed CUDA rank
// (cuda/dfsph_solver.cu; an undivided CUDA world runs the same loop on the device,
// cuda/dfsph_solve_loop.cuh, by the same stopping rule). In a distributed world this is where
// the ghosts are refreshed between the passes (docs/distributed.md): each velocity update is
// followed by the ghosts taking their owners' velocities (the rate pass reads its neighbours'),
// each rate pass by their taking their owners' pressure steps k (the next velocity update reads
// them), and the mean error is the world's (each rank's exact sum, its bins added over the ranks),
// so every rank takes the same decision as the undivided world. Undivided, the shares do nothing.
#pragma once

#include <stdint.h>

#include "../physics/host_device.h"

namespace sph {

// The stopping rule, after the initial residual (iterations 0) and after each iteration: on while
// the error is above the bound or the minimum has not run, and below the cap.
SPH_HD bool dfsph_solve_goes_on(float error, uint32_t iterations, float bound, uint32_t min_iterations,
                                uint32_t max_iterations) {
  return (error > bound || iterations < min_iterations) && iterations < max_iterations;
}

struct DfsphLoopOutcome {
  uint32_t iterations;  // after the initial residual
  float error;          // the mean error the solve ended with
  bool capped;          // stopped at the cap with the error above the bound
};

// Runs the solve on `passes`, which provides (each on the rank's own particles and its ghosts):
//   void velocity_update(bool warm)  v += the velocity change of the pressure steps k (warm: the
//                                    warm start's steps, the first update of the solve)
//   void share_velocities()          a rank's ghosts take their owners' velocities
//   void rates()                     each particle's rate of density change, new k and error
//   void share_steps()               a rank's ghosts take their owners' k
//   float mean_error()               the mean error over the world's particles (ghosts left out)
//   void checked(uint32_t iterations, float error, bool goes_on)   after each test (a record)
template <class Passes>
DfsphLoopOutcome run_dfsph_jacobi(Passes& passes, float bound, uint32_t min_iterations,
                                  uint32_t max_iterations) {
  auto iteration = [&](bool warm) {
    passes.velocity_update(warm);
    passes.share_velocities();  // the next rate pass reads the ghosts' velocities
    passes.rates();
    passes.share_steps();  // the next velocity update reads the ghosts' k
    return passes.mean_error();
  };
  float error = iteration(true);
  uint32_t iterations = 0;
  bool more = dfsph_solve_goes_on(error, iterations, bound, min_iterations, max_iterations);
  passes.checked(iterations, error, more);
  while (more) {
    error = iteration(false);
    ++iterations;
    more = dfsph_solve_goes_on(error, iterations, bound, min_iterations, max_iterations);
    passes.checked(iterations, error, more);
  }
  return DfsphLoopOutcome{iterations, error, error > bound};
}

}  // namespace sph
