// SPDX-License-Identifier: MIT
// The record of DFSPH's solves over a frame, written once for both backends: each substep adds
// one solve's iterations, achieved error and whether it stopped at its cap (the CPU backend on
// the stack of its frame, the CUDA backend in FrameState from its convergence kernel), and the
// frame's report is finished from the tally (sph_stats; a capped solve is also an event).
#pragma once

#include <float.h>
#include <stdint.h>

#include "../physics/host_device.h"
#include "frame_report.h"

namespace sph {

struct SolveTally {
  double error_sum;  // of the achieved errors, in the order the substeps ran
  float error_max;
  uint32_t solves;  // substeps that ran the solve
  uint32_t iterations;
  uint32_t iterations_max;
  uint32_t capped;
  float largest_max;  // the largest particle error any of the solves ended with
  uint32_t guarded;   // solves the Chebyshev guard turned to plain steps (dfsph_chebyshev.h)
};

SPH_HD SolveTally empty_solve_tally() { return SolveTally{0.0, 0.0f, 0u, 0u, 0u, 0u, 0.0f, 0u}; }

// One substep's solve: `iterations` after the initial residual, the mean error and the largest
// particle error it ended with, whether it stopped at the cap with a bound unmet, and whether the
// Chebyshev solve's guard made it finish with plain steps.
SPH_HD void record_solve(SolveTally& t, uint32_t iterations, float error, float largest, bool capped,
                         bool guarded) {
  t.error_sum += error;
  t.error_max = t.error_max < error ? error : t.error_max;
  t.largest_max = t.largest_max < largest ? largest : t.largest_max;
  t.solves += 1;
  t.iterations += iterations;
  t.iterations_max = t.iterations_max < iterations ? iterations : t.iterations_max;
  t.capped += capped ? 1u : 0u;
  t.guarded += guarded ? 1u : 0u;
}

inline SolveReport finish_solve(const SolveTally& t) {
  SolveReport r;
  r.iterations = t.iterations;
  r.iterations_max = t.iterations_max;
  r.capped = t.capped;
  r.error_mean = t.solves > 0 ? static_cast<float>(t.error_sum / t.solves) : 0.0f;
  r.error_max = t.error_max;
  r.largest_max = t.largest_max;
  r.guarded = t.guarded;
  return r;
}

}  // namespace sph
