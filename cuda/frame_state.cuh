// SPDX-License-Identifier: MIT
// The frame's bookkeeping, kept on the device so that the substep loop decides its own next
// step size and its own end without a round trip to the host. One per world.
#pragma once

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../src/core/density_record.h"
#include "../src/core/frame_report.h"
#include "../src/core/non_finite.h"
#include "../src/core/solver_record.h"
#include "../src/core/substep_clock.h"

namespace sph {

constexpr int kRk4Stages = 4;
constexpr unsigned long long kNoBadParticle = ~0ull;

// What the host writes before each frame (one copy from pinned memory into the head of
// FrameState).
struct FrameInput {
  double frame_dt;
  float max_collider_speed;  // fastest collider surface point, m/s (0 without colliders)
  uint32_t pad;
};

struct FrameState {
  // Input, written by the host before each frame (FrameInput's layout).
  double frame_dt;
  float max_collider_speed;
  uint32_t input_pad;

  SubstepClock clock;      // the substep loop, advanced as on the CPU (substep_clock.h)
  float max_speed;         // |v|max after the last substep; persists across frames
  float saved_max_speed;   // max_speed at the start of the frame, for a rollback
  uint32_t run;            // 1 while the loop goes on
  uint32_t non_finite;     // 1 once a substep produced NaN/Inf
  uint32_t v2max_bits;     // max |v|^2 of this substep as float bits (non-negative: uint order)
  uint32_t a2max_bits;     // max |a|^2 of this substep's force evaluations, likewise
  float max_acceleration;  // |a|max of the last substep, for the force step limit; persists
  uint32_t bad_id;         // id of the first non-finite particle
  uint32_t bad_substep;
  float bad_dt;
  uint32_t bad_stage;                     // NonFiniteStage of that particle
  uint32_t bad_count;                     // non-finite particles of the RK4 stage (or Euler step) that failed
  float saved_max_acceleration;           // max_acceleration at the start of the frame, for a rollback
  float emission_saved_max_speed;         // max_speed before a step's emission (save_step_inputs)
  float emission_saved_max_acceleration;  // likewise max_acceleration
  uint32_t emission_saved_link_from;      // likewise the springs' lowest waiting id (with springs)
  // DFSPH's depth limit (step_control.h): the lowest and highest x . g/|g| of the particles the
  // next step starts from, as order-preserving keys (height_key; atomicMin/atomicMax), reset
  // before each measurement (enqueue_height_span), and H = hi - lo as the step was picked with.
  uint32_t height_lo_key;
  uint32_t height_hi_key;
  float fluid_height;
  // Per RK4 stage (symplectic Euler uses [0]): ((sorted index << 2 | NonFiniteStage) << 32 | id),
  // the minimum wins, which is the particle the CPU backend names (indices < 2^30 = capacity).
  unsigned long long bad_key[kRk4Stages];
  uint32_t bad_counts[kRk4Stages];  // non-finite particles flagged per stage
  // A grid slot over the crowd cap (src/core/crowded_cell.h): (held << 32 | slot) of the most
  // crowded one, the largest key winning; 0 when none. The substep that finds it ends the frame.
  unsigned long long crowded_key;
  float crowded_where[3];  // the position of that slot's first sorted particle, for the message

  DensityRecord density;  // of the last density evaluation, computed once at the end of the frame

  // DFSPH (dfsph_solver.cu): the frame's record of its two solves, and the solve that runs now.
  SolveTally pressure_tally;
  SolveTally divergence_tally;
  uint32_t solve_run;           // 1 while the current solve iterates (the stream driver reads it)
  uint32_t solve_iterations;    // of the current solve, after its initial residual
  float solve_error;            // the current solve's mean error
  float solve_largest;          // and its largest particle error (the density solve's only)
  uint32_t solve_largest_bits;  // the largest of the measurement in progress, as float bits (atomicMax)
  float solve_weight;           // SPH_DFSPH_CHEBYSHEV: the next residual pass's weight (dfsph_chebyshev.h)
  float solve_smallest;         // and its guard (DfsphChebyshevGuard, dfsph_chebyshev.h), kept by the
  uint32_t solve_plain;         // check kernels: the smallest mean error so far; nonzero: the plain step
  // The conjugate gradients' density solve (dfsph_cg_solver.cu): a new cycle is due; the rest of
  // this iteration is skipped (no descent along p, or a restart); a contact was held in it; the
  // largest error outside the active set of the measurement in progress (float bits, atomicMax);
  // value . z over the active set; the step along p and the next direction's share of p.
  uint32_t cg_restart;
  uint32_t cg_skip;
  uint32_t cg_held;
  uint32_t cg_outside_largest_bits;
  double cg_sz;
  float cg_alpha;
  float cg_beta;

  // Stage timing: the first thread of each stage's first kernel reads the GPU's global
  // nanosecond timer and charges the time since the previous mark to the previous stage.
  uint32_t timing_stage;
  unsigned long long timing_last_ns;
  unsigned long long stage_ns[kStageCount];
};

// A float as a key whose unsigned order is the float order (negative values included), and back:
// the height span's lowest and highest projections reduce by atomicMin/atomicMax on the keys, and
// a distributed rank's keys by integer min/max over the ranks. The reset keys (0xffffffff for the
// lowest, 0 for the highest) read back as NaN: height_of_span gives 0 for them.
SPH_HD uint32_t height_key(float value) {
  uint32_t bits;
  memcpy(&bits, &value, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}
SPH_HD float height_of_key(uint32_t key) {
  const uint32_t bits = (key & 0x80000000u) ? (key & 0x7fffffffu) : ~key;
  float value;
  memcpy(&value, &bits, sizeof value);
  return value;
}
constexpr uint32_t kHeightLoReset = 0xffffffffu;
constexpr uint32_t kHeightHiReset = 0u;

static_assert(offsetof(FrameState, frame_dt) == offsetof(FrameInput, frame_dt) &&
                  offsetof(FrameState, max_collider_speed) == offsetof(FrameInput, max_collider_speed),
              "FrameInput is the head of FrameState");

#if defined(__CUDACC__)
__device__ __forceinline__ unsigned long long global_timer_ns() {
  unsigned long long t;
  asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(t));
  return t;
}

// Called at the top of a stage's first kernel by every thread; one thread records.
__device__ __forceinline__ void mark_stage(FrameState* s, int next_stage) {
  if (blockIdx.x == 0 && threadIdx.x == 0) {
    const unsigned long long now = global_timer_ns();
    s->stage_ns[s->timing_stage] += now - s->timing_last_ns;
    s->timing_last_ns = now;
    s->timing_stage = static_cast<uint32_t>(next_stage);
  }
}
#endif

}  // namespace sph
