// SPDX-License-Identifier: MIT
// The single-thread kernels that run the frame loop on the device: start a frame, and after
// each substep take the max-speed reduction, check for non-finite values, advance the clock
// and pick the next step with the shared step control (controller_dt, landing_dt). In a CUDA
// graph they also set the WHILE node's condition.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/physics/float4_types.h"
#include "../src/physics/step_control.h"
#include "frame_state.cuh"

namespace sph {

// Where the loop's condition goes: a graph's conditional handle, or nowhere (the host reads
// FrameState::run instead).
struct LoopCondition {
  cudaGraphConditionalHandle handle = 0;
  bool in_graph = false;
};

// Reads FrameState::frame_dt (the host copies it in first), resets the frame's counters and
// timing, saves max_speed for a rollback, and picks the first step.
void enqueue_begin_frame(FrameState* state, const StepLimits& limits, uint32_t max_substeps,
                         LoopCondition cond, cudaStream_t stream);

// After the force pass of the last stage. stages: 1 (Euler) or 4 (RK4).
void enqueue_end_substep(FrameState* state, const StepLimits& limits, uint32_t max_substeps, int stages,
                         LoopCondition cond, cudaStream_t stream);

// max_speed = max |velocity[i]| over [0, n): what the CPU backend computes lazily after
// particles were added.
void enqueue_recompute_max_speed(const Float4* velocity, uint32_t n, FrameState* state, cudaStream_t stream);

// DFSPH's depth limit (step_control.h): the lowest and highest x . g/|g| of position[0, n) into
// the state's height keys, which the next step's pick reads (begin frame, end of substep). ghost:
// a distributed rank's ghost mask in the same order (null: every particle counts).
void enqueue_height_span(const Float4* position, const uint32_t* ghost, uint32_t n, const StepLimits& limits,
                         FrameState* state, cudaStream_t stream);

// max_speed = saved_max_speed, after a rollback.
void enqueue_restore_max_speed(FrameState* state, cudaStream_t stream);

}  // namespace sph
