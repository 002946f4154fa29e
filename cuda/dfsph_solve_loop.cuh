// SPDX-License-Identifier: MIT
// What DFSPH's device solves share (dfsph_solver.cu's Jacobi solves, dfsph_cg_solver.cu's
// conjugate gradients): the loop that runs an iteration's kernels while the device says so (a
// conditional WHILE node of the graph being captured, or chunks on the stream with one read of
// the flag per chunk), the sums in a fixed order (every block's tree, then the block sums in one
// block: the same additions in the same order every run, so iteration counts and results are the
// same bits), and the stopping rule with its record.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/dfsph_jacobi_loop.h"
#include "../src/core/exact_float_sum.h"
#include "../src/core/host_memory.h"
#include "../src/core/solver_record.h"
#include "../src/physics/dfsph_chebyshev.h"
#include "cuda_status.h"
#include "dfsph_solver.h"
#include "frame_control.h"
#include "frame_state.cuh"
#include "graph_while_node.h"

namespace sph {

// Threads of the one-block kernels that sum the block sums and decide.
constexpr unsigned kDfsphCheckBlock = 256;

// The candidates the solves' passes visit: the neighbour lists where the world keeps them, the
// masks where it keeps those, every candidate otherwise (physics/neighbor_walk.h).
__device__ inline ListedCandidates solve_walk(const ParticleArrays& a) {
  return ListedCandidates{a.dfsph_neighbor_mask, a.dfsph_neighbor_list, a.dfsph_list_stride};
}

// After the solve's test number `iterations` (0: the first) found the mean error `mean` (`bound`
// the solve's bound on it): the
// Chebyshev solve's guard (DfsphChebyshevGuard, dfsph_chebyshev.h; its fields in the state) and what the
// next residual pass applies, its weight or (solve_plain) the plain step. Called for
// SPH_DFSPH_CHEBYSHEV's density solve only, so that solve_plain, which the solve's record counts,
// is set by no other solve. One thread.
__device__ inline void dfsph_chebyshev_after_test(FrameState* state, uint32_t iterations, float mean,
                                                  float bound) {
  DfsphChebyshevGuard guard;
  guard.smallest = state->solve_smallest;
  guard.plain = state->solve_plain;
  chebyshev_guard_check(guard, iterations, mean, bound);
  state->solve_smallest = guard.smallest;
  state->solve_plain = guard.plain;
  state->solve_weight = chebyshev_guarded_pass(guard, iterations + 1u).weight;  // (with solve_plain)
}

// Fixed-shape tree over a block's shared slots: the same additions in the same order every run.
template <unsigned kBlock>
__device__ void block_tree_sum(double* slots) {
  for (unsigned stride = kBlock / 2; stride > 0; stride >>= 1) {
    __syncthreads();
    if (threadIdx.x < stride) slots[threadIdx.x] += slots[threadIdx.x + stride];
  }
  __syncthreads();
}

// The block's sum of `value` into partials[blockIdx.x]. Called by every thread of the block
// (kDfsphSolveBlock threads); may be called more than once in a kernel.
__device__ inline void dfsph_block_sum_to(double* partials, double value) {
  __shared__ double slots[kDfsphSolveBlock];
  __syncthreads();  // a previous call's slots are read
  slots[threadIdx.x] = value;
  block_tree_sum<kDfsphSolveBlock>(slots);
  if (threadIdx.x == 0) partials[blockIdx.x] = slots[0];
}

// The sum of `blocks` block sums, in every thread of a kDfsphCheckBlock-thread block.
__device__ inline double dfsph_sum_partials(const double* partials, uint32_t blocks) {
  __shared__ double slots[kDfsphCheckBlock];
  __syncthreads();  // a previous call's result is read
  double sum = 0.0;
  for (uint32_t b = threadIdx.x; b < blocks; b += kDfsphCheckBlock) sum += partials[b];
  slots[threadIdx.x] = sum;
  block_tree_sum<kDfsphCheckBlock>(slots);
  return slots[0];
}

// The block's largest particle error into *largest (errors are >= 0, so their
// float bits order as the floats; the maximum is the same whatever order the blocks run in). Called
// by every thread of the block; a NaN counts as 0 here (the mean carries it).
// `largest`: FrameState::solve_largest_bits, or a distributed rank's word after its exact bins.
template <class Word>
__device__ inline void dfsph_block_max_to(Word* largest, float error) {
  __shared__ unsigned block_largest;
  const unsigned bits = __reduce_max_sync(0xffffffffu, __float_as_uint(error > 0.0f ? error : 0.0f));
  if (threadIdx.x == 0) block_largest = 0u;
  __syncthreads();
  if ((threadIdx.x & 31u) == 0u && bits != 0u) atomicMax(&block_largest, bits);
  __syncthreads();
  if (threadIdx.x == 0 && block_largest != 0u) atomicMax(largest, static_cast<Word>(block_largest));
}

// Adds x (when `own`) into the exact sum's bins (core/exact_float_sum.h, int64 as two's
// complement): the block's into shared bins, then its nonzero bins into the device's. Integer
// additions, so any order of the threads and blocks gives the same bins. Every thread calls it;
// calls in a row reuse the shared bins (each thread clears and flushes the same ones).
__device__ inline void exact_bins_add(unsigned long long* bins, bool own, float x) {
  __shared__ unsigned long long local[ExactFloatSum::kTerms];
  for (unsigned b = threadIdx.x; b < ExactFloatSum::kTerms; b += blockDim.x) local[b] = 0ull;
  __syncthreads();
  if (own) {
    const ExactFloatTerm t = exact_float_term(__float_as_uint(x));
    atomicAdd(&local[t.bin], static_cast<unsigned long long>(t.term));
  }
  __syncthreads();
  for (unsigned b = threadIdx.x; b < ExactFloatSum::kTerms; b += blockDim.x)
    if (local[b] != 0ull) atomicAdd(&bins[b], local[b]);
}

// The measurement's largest particle error into state->solve_largest, ready for the next. One thread.
__device__ inline void dfsph_take_largest(FrameState* state) {
  state->solve_largest = __uint_as_float(state->solve_largest_bits);
  state->solve_largest_bits = 0u;
}

// The current solve's errors.
__device__ inline DfsphErrors dfsph_solve_errors(const FrameState* state) {
  return {state->solve_error, state->solve_largest};
}

// Ends the current solve: its record (the iterations and mean error it reached; capped when a
// bound is unmet, dfsph.h) and the loop's flag and condition. One thread.
__device__ inline void dfsph_stop_solve(FrameState* state, SolveTally& tally, const DfsphBounds& bounds,
                                        LoopCondition cond) {
  record_solve(tally, state->solve_iterations, state->solve_error, state->solve_largest,
               dfsph_bounds_unmet(bounds, dfsph_solve_errors(state)), state->solve_plain != 0u);
  state->solve_run = 0;
  if (cond.in_graph) cudaGraphSetConditional(cond.handle, 0u);
}

// The loop's test after an iteration (or the initial residual), the rule the host-driven loops
// share (core/dfsph_jacobi_loop.h). One thread.
__device__ inline void dfsph_continue_solve(FrameState* state, SolveTally& tally, const DfsphBounds& bounds,
                                            uint32_t min_iterations, uint32_t max_iterations,
                                            LoopCondition cond) {
  const bool more = dfsph_solve_goes_on(dfsph_solve_errors(state), state->solve_iterations, bounds,
                                        min_iterations, max_iterations);
  if (!more) {
    dfsph_stop_solve(state, tally, bounds, cond);
    return;
  }
  if (cond.in_graph) cudaGraphSetConditional(cond.handle, 1u);
}

// A conditional handle on the graph the stream is being captured into.
inline LoopCondition open_solve_loop(bool in_graph, cudaStream_t stream) {
  LoopCondition cond;
  if (!in_graph) return cond;
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  cudaGraph_t graph = nullptr;
  cuda_check(cudaStreamGetCaptureInfo(stream, &status, nullptr, &graph, nullptr, nullptr, nullptr),
             "cudaStreamGetCaptureInfo");
  cuda_check(cudaGraphConditionalHandleCreate(&cond.handle, graph, 0, cudaGraphCondAssignDefault),
             "cudaGraphConditionalHandleCreate");
  cond.in_graph = true;
  return cond;
}

// Runs iteration() while the check says so: a WHILE node in the graph being captured
// (graph_while_node.h), or chunks on the stream with one read of the flag per chunk (each kernel does nothing
// once the solve has stopped).
template <class Iteration>
void run_solve_loop(const LoopCondition& cond, FrameState* state, FrameState* host_state, cudaStream_t stream,
                    Iteration&& iteration) {
  if (!cond.in_graph) {
    for (;;) {
      cuda_check(cudaMemcpyAsync(&host_state->solve_run, &state->solve_run, sizeof(uint32_t),
                                 cudaMemcpyDeviceToHost, stream),
                 "copy of the solve's flag");
      cuda_check(cudaStreamSynchronize(stream), "solve");
      if (!host_state->solve_run) return;
      for (uint32_t k = 0; k < kDfsphSolveChunk; ++k) iteration();
    }
  }
  capture_while_node(cond.handle, stream, iteration);
}

}  // namespace sph
