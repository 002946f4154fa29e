// SPDX-License-Identifier: MIT
// What a backend reports about one frame (one sph_world_step).
#pragma once

#include <stdint.h>

#include <vector>

#include "../physics/probe_sampling.h"
#include "host_memory.h"

namespace sph {

enum StageIndex : int {
  kStageHashSort = 0,
  kStageCellRanges = 1,
  kStageDensity = 2,
  kStageForces = 3,
  kStageIntegrate = 4,
  kStageCollide = 5,
  kStageEmit = 6,
  kStageOther = 7,
  kStageCount = 8,
};

// One DFSPH solve (the density solve or the divergence solve) over the substeps of a frame
// (solver_record.h tallies it; zero on a weakly compressible world).
struct SolveReport {
  uint32_t iterations = 0;      // summed over the frame's substeps
  uint32_t iterations_max = 0;  // most in one substep
  uint32_t capped = 0;          // substeps whose solve stopped at its iteration cap above its bound
  float error_mean = 0.0f;      // the achieved mean error, averaged over the substeps
  float error_max = 0.0f;       // the largest of any substep
  float largest_max = 0.0f;     // the largest particle error any substep's solve ended with
  uint32_t guarded = 0;         // substeps whose Chebyshev density solve its guard turned to plain
                                // steps (dfsph_chebyshev.h); 0 for every other solve
};

// One collider's impulses over a frame (SPH_FEATURE_COLLIDER_LOADS, physics/collider_loads.h),
// summed in double in a fixed order.
struct ColliderLoadSums {
  double linear[3] = {0.0, 0.0, 0.0};   // N s, world frame
  double angular[3] = {0.0, 0.0, 0.0};  // N m s, about the load point
};

struct FrameReport {
  uint32_t substeps = 0;
  bool completed = true;       // false when max_substeps ran out before the frame's end
  bool interrupted = false;    // the step budget or a cancel stopped the frame (completed is false)
  double time_advanced = 0.0;  // seconds
  float dt_min = 0.0f;
  float dt_max = 0.0f;
  float max_speed = 0.0f;
  float density_min = 0.0f;
  float density_mean = 0.0f;
  float density_max = 0.0f;
  float neighbors_mean = 0.0f;
  uint32_t neighbors_max = 0;
  float stage_ms[kStageCount] = {};
  // Of stage_ms, the time a distributed world's rank spent inside its transport's calls
  // (RankTransport::times: the wait for the slowest rank and the transfer), and of that the
  // waits at the barriers MpiTransport::wait_at_barriers puts before them. The CPU backend
  // fills them; zero on an undivided world and, as it does not split its stages so, on CUDA ranks.
  float transport_ms[kStageCount] = {};
  float transport_wait_ms[kStageCount] = {};
  SolveReport pressure_solve;            // DFSPH's density solve: error dimensionless, (rho* - rho0)+ / rho0
  SolveReport divergence_solve;          // DFSPH's divergence solve: error in 1/s, (D rho / Dt)+ / rho0
  HostVector<uint32_t> removed_ids;      // ids sinks removed during the frame
  HostVector<uint32_t> removed_by_sink;  // count per sink, in SceneFrame::sinks order
  HostVector<ColliderLoadSums> collider_loads;  // per collider in SceneFrame::colliders order (loads on)
  HostVector<ProbeSums> probes;                 // per probe in SceneFrame::probes order
};

}  // namespace sph
