// SPDX-License-Identifier: MIT
// The order of device work in a frame, written once and used two ways: captured into a CUDA
// graph (frame_graph.h) or launched directly on the stream (the fallback). A frame is
//   begin:    frame_dt in, counters reset, first step chosen, state snapshot
//   substep:  (hash, sort, cell starts, reorder, density, forces + integrate) x 1 or 4 stages,
//             or DFSPH's (hash, sort, cell starts, reorder, density and factor, its solves and the
//             step: dfsph_solver.h), then the end-of-substep kernel (max speed, non-finite
//             check, clock, next step)
//   end:      statistics, FrameState out to pinned host memory
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/config.h"
#include "device_collider_loads.h"
#include "device_neighbor_grid.h"
#include "device_particle_store.h"
#include "device_probes.h"
#include "device_springs.h"
#include "dfsph_solver.h"
#include "frame_control.h"
#include "frame_statistics.h"
#include "substep_kernels.h"

namespace sph {

struct PipelineSetup {
  uint32_t count = 0;   // particles
  uint32_t ghosts = 0;  // of them, a distributed rank's ghosts (the statistics leave them out)
  Integrator integrator = Integrator::SymplecticEuler;
  FluidConstants fluid{};
  StepLimits limits{};
  uint32_t max_substeps = 1;
  SubstepOptions options{};
  KernelTuning tuning{};
  DeviceScene scene{};        // colliders and force fields inside the substep (none: all zero)
  SpringConstants springs{};  // used when options.springs
  DeviceLoads loads{};        // loads on colliders (off: all null)
  DeviceProbes probes{};      // probes and gauges (none: all null)
};

struct PipelineBuffers {
  const DeviceParticleStore* store;
  DeviceNeighborGrid* grid;
  const FrameStatistics* statistics;
  FrameState* state;         // device
  const FrameInput* input;   // pinned host, copied into the head of *state
  FrameState* state_output;  // pinned host, receives the state at the end
  double* solve_partials;    // DFSPH: the block sums of a solve's error (null otherwise)
};

// A distributed rank's host steps inside a substep (cuda_halo.cu; the stream driver only, as
// each may wait for the stream): the sort's visit order, and calls after the sort (the grid's
// order and cell starts are enqueued), after the density pass (the ghosts take their owners'
// densities) and before the end-of-substep kernel (the maxima and failures reduced over ranks);
// with DFSPH, after its density pass and inside its solves (DfsphRankSteps); with RK4, between
// its stages; with springs, between linking's two passes (SpringRankStep).
struct SubstepHooks : DfsphRankSteps, SpringRankStep {
  const uint32_t* visit = nullptr;
  // RK4: before stage `stage` (1-3) sorts, the last one ends as a substep does on the CPU rank: a
  // failure agreed over the ranks (false: every rank ends the substep there, and before_end
  // reduces what failed), the ghosts dropped, the halo gathered anew (migrants with the stage
  // state); *count becomes the rank's particles and ghosts.
  virtual bool next_stage(int stage, uint32_t* count, cudaStream_t stream) = 0;
  virtual void after_sort(cudaStream_t stream) = 0;
  virtual void after_density(cudaStream_t stream) = 0;
  virtual void after_dfsph_density(cudaStream_t stream) = 0;  // DFSPH's density pass
  virtual void after_normals(cudaStream_t stream) = 0;        // surface tension's colour normals
  // Probes: each sample point's gather (probes.points, device) replaced by its owner rank's.
  virtual void after_probe_points(const DeviceProbes& probes, cudaStream_t stream) = 0;
  virtual void before_end(cudaStream_t stream) = 0;
};

// measure_height: DFSPH's depth limit measures H from the frame's positions here (false: a
// distributed rank's, measured and reduced over the ranks in halo_begin_frame).
void enqueue_frame_begin(const PipelineSetup& setup, const PipelineBuffers& b, LoopCondition cond,
                         cudaStream_t stream, bool measure_height = true);
// hooks: a distributed rank's (null otherwise).
void enqueue_substep(const PipelineSetup& setup, const PipelineBuffers& b, LoopCondition cond,
                     cudaStream_t stream, SubstepHooks* hooks = nullptr);
// counts: the neighbour counts of the last density pass when a sink compaction left the sorted
// copy behind (FrameStatistics::enqueue); null otherwise.
void enqueue_frame_end(const PipelineSetup& setup, const PipelineBuffers& b, cudaStream_t stream,
                       const uint32_t* counts = nullptr);

}  // namespace sph
