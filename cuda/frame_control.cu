// SPDX-License-Identifier: MIT
#include "block_reduce.cuh"
#include "frame_control.h"
#include "kernel_launch.h"

namespace sph {
namespace {

// The CPU backend's step choice (substep_clock.h): the controller sees the faster of the fluid
// and the colliders' surfaces, so a fast paddle cannot skip a particle between substeps.
// DFSPH's depth limit reads H from the keys its last measurement left (enqueue_height_span; a
// distributed rank's were reduced over the ranks), 0 where the limit is off.
__device__ void pick_step(FrameState* s, const StepLimits& limits) {
  s->fluid_height = limits.depth_step_factor > 0.0f
                        ? height_of_span(height_of_key(s->height_lo_key), height_of_key(s->height_hi_key))
                        : 0.0f;
  pick_next_step(s->clock, s->frame_dt, limits, fmaxf(s->max_speed, s->max_collider_speed),
                 s->max_acceleration, s->fluid_height);
}

__device__ void set_run(FrameState* s, uint32_t run, const LoopCondition& cond) {
  s->run = run;
  if (cond.in_graph) cudaGraphSetConditional(cond.handle, run);
}

__global__ void begin_frame_kernel(FrameState* s, StepLimits limits, uint32_t max_substeps,
                                   LoopCondition cond) {
  s->timing_last_ns = global_timer_ns();
  s->timing_stage = kStageOther;
  for (int k = 0; k < kStageCount; ++k) s->stage_ns[k] = 0;
  start_clock(s->clock, s->frame_dt);
  s->non_finite = 0;
  s->v2max_bits = 0;
  s->a2max_bits = 0;
  s->bad_id = 0;
  s->bad_substep = 0;
  s->bad_dt = 0.0f;
  s->bad_stage = 0;
  s->bad_count = 0;
  s->saved_max_acceleration = s->max_acceleration;
  for (int k = 0; k < kRk4Stages; ++k) {
    s->bad_key[k] = kNoBadParticle;
    s->bad_counts[k] = 0;
  }
  s->crowded_key = 0;
  s->saved_max_speed = s->max_speed;
  s->pressure_tally = empty_solve_tally();
  s->divergence_tally = empty_solve_tally();
  s->solve_run = 0;
  s->solve_iterations = 0;
  s->solve_error = 0.0f;
  s->solve_largest = 0.0f;
  s->solve_largest_bits = 0u;
  const uint32_t run = clock_running(s->clock, max_substeps) ? 1u : 0u;
  if (run) pick_step(s, limits);
  set_run(s, run, cond);
}

__global__ void end_substep_kernel(FrameState* s, StepLimits limits, uint32_t max_substeps, int stages,
                                   LoopCondition cond) {
  mark_stage(s, kStageIntegrate);
  const float v2max = __uint_as_float(s->v2max_bits);
  const float a2max = __uint_as_float(s->a2max_bits);
  s->v2max_bits = 0;
  s->a2max_bits = 0;
  // As the CPU backend: symplectic Euler keeps the force pass's |a|max even when the substep
  // then fails; RK4 keeps the max over its four stages only when all of them succeeded.
  if (stages == 1) s->max_acceleration = sqrtf(a2max);
  for (int k = 0; k < stages; ++k) {
    if (s->bad_key[k] != kNoBadParticle) {
      s->non_finite = 1;
      s->bad_id = static_cast<uint32_t>(s->bad_key[k] & 0xffffffffu);
      s->bad_stage = static_cast<uint32_t>((s->bad_key[k] >> 32) & 3u);
      s->bad_count = s->bad_counts[k];
      s->bad_substep = s->clock.substeps + 1;
      s->bad_dt = s->clock.dt_float;
      set_run(s, 0, cond);
      return;
    }
  }
  // After the non-finite check: a NaN position of one RK4 stage hashes into one cell with every
  // other NaN at the next stage's sort, and the cause to report is the NaN. A pile crowded from
  // the start leaves every value finite (an emptied table gives each particle its self density).
  if (s->crowded_key != 0) {
    // The walks of this substep saw an emptied table (enqueue_reorder); the frame is refused.
    // non_finite stops the stream driver's sinks as for a failed substep; bad_substep stays 0,
    // which is how the host tells the two apart (frame_loop.cu).
    s->non_finite = 1;
    set_run(s, 0, cond);
    return;
  }
  s->max_speed = sqrtf(v2max);
  if (stages != 1) s->max_acceleration = sqrtf(a2max);
  advance_clock(s->clock);
  const uint32_t run = clock_running(s->clock, max_substeps) ? 1u : 0u;
  if (run) pick_step(s, limits);
  set_run(s, run, cond);
}

__global__ void speed_max_kernel(const Float4* __restrict__ velocity, uint32_t n, FrameState* s) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  block_max_to(&s->v2max_bits, i < n ? length_squared(xyz(velocity[i])) : 0.0f);
}

// The lowest and highest x . g/|g| of the particles [0, n) (a distributed rank's ghosts left out:
// their owners hold them), reduced over the block, then one atomicMin/atomicMax per block on the
// keys: exact in any order, as the CPU backend's reduction (cpu_frame_control.cpp).
__global__ void height_span_kernel(const Float4* __restrict__ position, const uint32_t* __restrict__ ghost,
                                   uint32_t n, StepLimits limits, FrameState* s) {
  __shared__ float warp_lo[32], warp_hi[32];
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  float lo = INFINITY, hi = -INFINITY;
  if (i < n && !(ghost && ghost[i])) {
    const float y = height_along(limits, xyz(position[i]));
    if (!isnan(y)) lo = hi = y;  // (fminf/fmaxf leave NaN out, as the CPU's fmin/fmax)
  }
  lo = block_reduce(lo, INFINITY, MinOp{}, warp_lo);
  hi = block_reduce(hi, -INFINITY, MaxOp{}, warp_hi);
  if (threadIdx.x == 0 && lo <= hi) {
    atomicMin(&s->height_lo_key, height_key(lo));
    atomicMax(&s->height_hi_key, height_key(hi));
  }
}

__global__ void reset_height_span_kernel(FrameState* s) {
  s->height_lo_key = kHeightLoReset;
  s->height_hi_key = kHeightHiReset;
}

__global__ void finish_speed_max_kernel(FrameState* s) {
  s->max_speed = sqrtf(__uint_as_float(s->v2max_bits));
  s->v2max_bits = 0;
}

// A rolled-back frame leaves the step controller's inputs as they were too.
__global__ void restore_max_speed_kernel(FrameState* s) {
  s->max_speed = s->saved_max_speed;
  s->max_acceleration = s->saved_max_acceleration;
}

}  // namespace

void enqueue_begin_frame(FrameState* state, const StepLimits& limits, uint32_t max_substeps,
                         LoopCondition cond, cudaStream_t stream) {
  begin_frame_kernel<<<1, 1, 0, stream>>>(state, limits, max_substeps, cond);
  check_launch("begin_frame_kernel");
}

void enqueue_end_substep(FrameState* state, const StepLimits& limits, uint32_t max_substeps, int stages,
                         LoopCondition cond, cudaStream_t stream) {
  end_substep_kernel<<<1, 1, 0, stream>>>(state, limits, max_substeps, stages, cond);
  check_launch("end_substep_kernel");
}

void enqueue_recompute_max_speed(const Float4* velocity, uint32_t n, FrameState* state, cudaStream_t stream) {
  cuda_check(cudaMemsetAsync(&state->v2max_bits, 0, sizeof(uint32_t), stream),
             "reset of the speed reduction");
  speed_max_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(velocity, n, state);
  check_launch("speed_max_kernel");
  finish_speed_max_kernel<<<1, 1, 0, stream>>>(state);
  check_launch("finish_speed_max_kernel");
}

void enqueue_height_span(const Float4* position, const uint32_t* ghost, uint32_t n, const StepLimits& limits,
                         FrameState* state, cudaStream_t stream) {
  reset_height_span_kernel<<<1, 1, 0, stream>>>(state);
  check_launch("reset_height_span_kernel");
  if (n == 0) return;
  height_span_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(position, ghost, n,
                                                                                         limits, state);
  check_launch("height_span_kernel");
}

void enqueue_restore_max_speed(FrameState* state, cudaStream_t stream) {
  restore_max_speed_kernel<<<1, 1, 0, stream>>>(state);
  check_launch("restore_max_speed_kernel");
}

}  // namespace sph
