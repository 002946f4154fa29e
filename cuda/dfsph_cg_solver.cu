// SPDX-License-Identifier: MIT
// DFSPH's density solve by Jacobi-preconditioned conjugate gradients on the device
// (sph_dfsph_params.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS; physics/dfsph_cg.h has the
// method; the twin of src/cpu/cpu_dfsph_cg.cpp, which it follows step by step). An iteration is a
// fixed list of kernels, so it runs in the Jacobi solve's loop (dfsph_solve_loop.cuh): the CPU
// driver's branches (a new cycle, no descent along p, a restart for the compression outside the
// set, dfsph_cg_restart_due) are flags in FrameState that the one-block kernels set and the particle kernels
// read, every thread of a kernel taking the same branch. The sums are block trees and one block's sum of the
// block sums (fixed order: the same bits every run; not the CPU's exact sums, so the two backends
// agree to rounding). The contacts: the CPU holds them in storage order, each held particle adding
// m dv . grad W_ij to its neighbours' values; a particle's hold depends on its own velocity alone,
// so here every particle holds its own and a gather adds the same terms (the rate of the held
// changes, dfsph_cg_change), one more neighbour pass in an iteration that held any. A distributed
// rank's solve is dfsph_cg_rank_solver.cu's; what both share, dfsph_cg_common.cuh.
#include "dfsph_cg_common.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

__device__ bool skipped(const CgSolve& s) { return s.state->solve_run == 0 || s.state->cg_skip != 0; }

// After the warm start: each particle's value rho* - rho0 over the velocities, the mean error,
// the loop's first test, a cycle due.
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_measure_kernel(CgSolve s) {
  if (s.state->solve_run == 0) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const double error = i < s.n ? cg_measure_particle(s, i) : 0.0f;
  dfsph_block_sum_to(s.partials, error);
  dfsph_block_max_to(&s.state->solve_largest_bits, static_cast<float>(error));
}

__global__ void __launch_bounds__(kDfsphCheckBlock) cg_first_check_kernel(CgSolve s) {
  FrameState* state = s.state;
  if (state->solve_run == 0) return;
  const double sum = dfsph_sum_partials(s.partials, s.blocks);
  if (threadIdx.x != 0) return;
  const Dfsph::Constants& c = s.fluid.methods.dfsph;
  state->solve_iterations = 0;
  state->solve_error = s.n > 0 ? static_cast<float>(sum / s.n) : 0.0f;
  dfsph_take_largest(state);
  state->cg_restart = 1;
  state->cg_skip = 0;
  state->cg_outside_largest_bits = 0u;  // (each measurement's check takes and clears it)
  dfsph_continue_solve(state, state->pressure_tally, dfsph_density_bounds(c), Dfsph::kMinIterations,
                       c.max_iterations, s.cond);
}

// A new cycle (when one is due): the set, the binding contacts, the steepest (preconditioned)
// direction, and the block sums of value . p over the set.
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_restart_kernel(CgSolve s) {
  if (s.state->solve_run == 0 || s.state->cg_restart == 0) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  double sz = 0.0;
  if (i < s.n) {
    const CgTerm t = cg_restart_particle(s, i);
    if (t.active) sz = static_cast<double>(t.value);
  }
  dfsph_block_sum_to(s.partials, sz);
}

// value . z of the new cycle; nothing that pressure can reach is off its rest density: done, once
// the minimum ran (as the Jacobi solve's, whose iterations then apply no pressure either).
__global__ void __launch_bounds__(kDfsphCheckBlock) cg_restart_check_kernel(CgSolve s) {
  FrameState* state = s.state;
  if (state->solve_run == 0 || state->cg_restart == 0) return;
  const double sz = dfsph_sum_partials(s.partials, s.blocks);
  if (threadIdx.x != 0) return;
  state->cg_sz = sz;
  state->cg_restart = 0;
  if (sz == 0.0 && state->solve_iterations >= Dfsph::kMinIterations)
    dfsph_stop_solve(state, state->pressure_tally, dfsph_density_bounds(s.fluid.methods.dfsph), s.cond);
}

// Second half: the change of each value from the rates of dv_p alone, and the block sums of
// p . A p (-p . change over the set).
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_change_kernel(CgSolve s) {
  if (s.state->solve_run == 0) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  double pq = 0.0;
  if (i < s.n) {
    const CgTerm t = cg_change_particle(s, i);
    if (t.active) pq = static_cast<double>(t.value);
  }
  dfsph_block_sum_to(s.partials, pq);
}

// The iteration counts; the step alpha = (value . z) / (p . A p), or, with no descent left along p
// (rounding), a new cycle from the same state.
__global__ void __launch_bounds__(kDfsphCheckBlock) cg_step_check_kernel(CgSolve s) {
  FrameState* state = s.state;
  if (state->solve_run == 0) return;
  const double pq = dfsph_sum_partials(s.partials, s.blocks);
  if (threadIdx.x != 0) return;
  state->solve_iterations += 1;
  state->cg_held = 0;
  if (!(pq > 0.0)) {
    state->cg_restart = 1;
    state->cg_skip = 1;
    return;
  }
  state->cg_alpha = static_cast<float>(state->cg_sz / pq);
  state->cg_skip = 0;
}

// The held contacts' changes added to the values (cg_held_value); each particle's error, and the
// block sums of the errors (partials [0, blocks)) and of those outside the set that a new set
// could take (a factor; [blocks, 2 blocks)); the largest error, and the largest of those outside
// the set (a maximum: the same whatever order the blocks run in).
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_error_kernel(CgSolve s) {
  if (skipped(s)) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  double error = 0.0, outside = 0.0;
  if (i < s.n) {
    const float z = dfsph_cg_error(cg_held_value(s, i), s.fluid.rest_density);
    error = z;
    if (!(s.a.dfsph_cg_state[i] & kCgActive) && s.a.dfsph_factor[i] > 0.0f) outside = z;
  }
  dfsph_block_sum_to(s.partials, error);
  dfsph_block_sum_to(s.partials + s.blocks, outside);
  dfsph_block_max_to(&s.state->solve_largest_bits, static_cast<float>(error));
  dfsph_block_max_to(&s.state->cg_outside_largest_bits, static_cast<float>(outside));
}

// The mean and largest errors; a restart when the compression outside the set needs a larger set
// (dfsph_cg_restart_due); the loop's test (also after an iteration without descent, with the error
// it had).
__global__ void __launch_bounds__(kDfsphCheckBlock) cg_error_check_kernel(CgSolve s) {
  FrameState* state = s.state;
  if (state->solve_run == 0) return;
  const Dfsph::Constants& c = s.fluid.methods.dfsph;
  const DfsphBounds bounds = dfsph_density_bounds(c);
  const bool measured = state->cg_skip == 0;  // uniform: the block reads it before any thread writes it
  double error = 0.0, outside = 0.0;
  if (measured) {
    error = dfsph_sum_partials(s.partials, s.blocks);
    outside = dfsph_sum_partials(s.partials + s.blocks, s.blocks);
  }
  if (threadIdx.x != 0) return;
  if (measured) {
    // (n > 0 here: with no particles p . A p is 0 and every iteration skips its measurement)
    state->solve_error = static_cast<float>(error / static_cast<double>(s.n));
    dfsph_take_largest(state);
    const float outside_largest = __uint_as_float(state->cg_outside_largest_bits);
    state->cg_outside_largest_bits = 0u;
    if (dfsph_cg_restart_due(bounds, outside / static_cast<double>(s.n), outside_largest)) {
      state->cg_restart = 1;
      state->cg_skip = 1;
    }
  }
  dfsph_continue_solve(state, state->pressure_tally, bounds, Dfsph::kMinIterations, c.max_iterations, s.cond);
}

// z (the Jacobi step) over the set, and the block sums of value . z.
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_residual_kernel(CgSolve s) {
  if (skipped(s)) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  double sz = 0.0;
  if (i < s.n) {
    const CgTerm t = cg_residual_particle(s, i, s.a.dfsph_cg_value[i]);
    if (t.active) sz = static_cast<double>(t.value);
  }
  dfsph_block_sum_to(s.partials, sz);
}

__global__ void __launch_bounds__(kDfsphCheckBlock) cg_beta_kernel(CgSolve s) {
  FrameState* state = s.state;
  if (skipped(s)) return;
  const double sz = dfsph_sum_partials(s.partials, s.blocks);
  if (threadIdx.x != 0) return;
  state->cg_beta = static_cast<float>(sz / state->cg_sz);
  state->cg_sz = sz;
}

// The operator on p, first half: the velocities p would give (cg_direction_particle).
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_direction_kernel(CgSolve s) {
  if (s.state->solve_run == 0) return;
  mark_stage(s.state, kStageForces);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < s.n) cg_direction_particle(s, i);
}

}  // namespace

// ---- The particle kernels without sums, which the rank's solve runs too (dfsph_cg_common.cuh) ----

// v += alpha dv_p, the pressure += alpha p, value += alpha change; then the contact held as the
// Jacobi solve holds it, its change kept in dv for the gather (0 where none was held).
__global__ void cg_update_kernel(CgSolve s) {
  if (skipped(s)) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= s.n) return;
  const float alpha = s.state->cg_alpha;
  const Float4 v = s.a.velocity[i];
  Vec3 vi = xyz(v) + xyz(s.a.dfsph_cg_velocity_step[i]) * alpha;
  s.a.dfsph_pressure[i] += alpha * s.a.dfsph_step[i];
  s.a.dfsph_cg_value[i] += alpha * s.a.dfsph_cg_change[i];
  if (s.contacts) {
    Vec3 held_change{0.0f, 0.0f, 0.0f};
    const Float4 contact = s.a.dfsph_contact[i];
    if (dfsph_contact_moved(contact, vi)) {
      const Vec3 held = respect_contact(contact, vi);
      held_change = held - vi;
      vi = held;
      s.a.dfsph_cg_state[i] |= kCgBinds;
      s.state->cg_held = 1;  // every writer writes 1
    }
    s.a.dfsph_cg_velocity_step[i] = make_float4_record(held_change, 0.0f);
  }
  s.a.velocity[i] = make_float4_record(vi, v.w);
}

// The next direction p = z + beta p over the set.
__global__ void cg_next_direction_kernel(CgSolve s) {
  if (skipped(s)) return;
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= s.n) return;
  const float beta = s.state->cg_beta;
  s.a.dfsph_step[i] =
      (s.a.dfsph_cg_state[i] & kCgActive) ? s.a.dfsph_residual[i] + beta * s.a.dfsph_step[i] : 0.0f;
}

// What the solve keeps of each pressure: its positive part (dfsph_cg_kept_pressure).
__global__ void cg_keep_kernel(float* pressure, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) pressure[i] = dfsph_cg_kept_pressure(pressure[i]);
}

void enqueue_dfsph_cg_solve(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                            uint32_t n, bool contacts, const DfsphLoops& loops, const LoopCondition& cond,
                            FrameState* state, cudaStream_t stream) {
  if (!a.dfsph_cg_value || !a.dfsph_residual)
    throw Error(Status::Internal, "DFSPH's conjugate gradients: the world has no arrays for them");
  const unsigned threads = kDfsphSolveBlock, blocks = blocks_for(n, threads);
  const CgSolve s{fluid, grid, a, n, contacts, blocks, cond, state, loops.partials};
  auto particles = [&](void (*kernel)(CgSolve), const char* name) {
    kernel<<<blocks, threads, 0, stream>>>(s);
    check_launch(name);
  };
  auto check = [&](void (*kernel)(CgSolve), const char* name) {
    kernel<<<1, kDfsphCheckBlock, 0, stream>>>(s);
    check_launch(name);
  };
  particles(cg_measure_kernel, "cg_measure_kernel");
  check(cg_first_check_kernel, "cg_first_check_kernel");
  run_solve_loop(cond, state, loops.host_state, stream, [&] {
    particles(cg_restart_kernel, "cg_restart_kernel");
    check(cg_restart_check_kernel, "cg_restart_check_kernel");
    particles(cg_direction_kernel, "cg_direction_kernel");
    particles(cg_change_kernel, "cg_change_kernel");
    check(cg_step_check_kernel, "cg_step_check_kernel");
    particles(cg_update_kernel, "cg_update_kernel");
    particles(cg_error_kernel, "cg_error_kernel");
    check(cg_error_check_kernel, "cg_error_check_kernel");
    particles(cg_residual_kernel, "cg_residual_kernel");
    check(cg_beta_kernel, "cg_beta_kernel");
    particles(cg_next_direction_kernel, "cg_next_direction_kernel");
  });
  cg_keep_kernel<<<blocks, threads, 0, stream>>>(a.dfsph_pressure, n);
  check_launch("cg_keep_kernel");
}

}  // namespace sph
