// SPDX-License-Identifier: MIT
// DFSPH's Jacobi solves on a distributed rank (include/sph_mpi.h): the host drives each solve an
// iteration at a time by core/dfsph_jacobi_loop.h, the CPU rank's loop, which says when the ghosts
// take their owners' velocities and pressure steps (DfsphRankSteps, cuda_halo.cu) and reads the
// world's errors (each rank's exact sum, added over the ranks) between the passes. The passes are
// the undivided solve's kernels (dfsph_solver.cu: the velocity update, the rates with the errors
// of the rank's own particles into the exact sum's bins); the test below writes the state and the
// record as the undivided world's check kernel does, by the same rule, so each rank decides as
// the undivided world would. (The conjugate gradients' rank solve: dfsph_cg_rank_solver.cu.)
//
// Compiled with dfsph_solver.cu's arithmetic (CMakeLists.txt): the Chebyshev weight written here
// must be the bits that its undivided check kernel writes (gpu_check_mpi compares the two worlds
// bit for bit).
#include "../src/core/dfsph_jacobi_loop.h"
#include "../src/physics/dfsph_chebyshev.h"
#include "dfsph_solve_loop.cuh"
#include "dfsph_solver.h"
#include "kernel_launch.h"

namespace sph {
namespace {

// A distributed rank's test, decided by the host (core/dfsph_jacobi_loop.h) on the world's
// errors: the state and the record as dfsph_check_kernel leaves them, by the same rule
// (`chebyshev`: SPH_DFSPH_CHEBYSHEV's density solve, the one its guard watches).
__global__ void dfsph_rank_check_kernel(uint32_t iterations, DfsphErrors errors, DfsphBounds bounds,
                                        uint32_t min_iterations, uint32_t max_iterations, bool divergence,
                                        bool chebyshev, FrameState* state) {
  state->solve_iterations = iterations;
  state->solve_error = errors.mean;
  if (chebyshev) dfsph_chebyshev_after_test(state, iterations, errors.mean, bounds.mean);
  state->solve_largest = errors.largest;
  dfsph_continue_solve(state, divergence ? state->divergence_tally : state->pressure_tally, bounds,
                       min_iterations, max_iterations, LoopCondition{});
}

}  // namespace

void enqueue_dfsph_jacobi_rank_solve(const FluidConstants& fluid, const GridView& grid,
                                     const ParticleArrays& a, uint32_t n, Float4* v, const float* warm,
                                     float* carried, bool divergence, bool contacts, uint32_t min_iterations,
                                     uint32_t max_iterations, DfsphRankSteps& rank, FrameState* state,
                                     cudaStream_t stream) {
  // The divergence bound depends on the substep's dt, which the device chose (the same on every
  // rank); the host reads it once a divergence solve (each iteration waits on the device anyway).
  float dt = 0.0f;
  if (divergence) {
    cuda_check(cudaMemcpyAsync(&dt, &state->clock.dt_float, sizeof dt, cudaMemcpyDeviceToHost, stream),
               "DFSPH rank solve: dt download");
    cuda_check(cudaStreamSynchronize(stream), "DFSPH rank solve: dt download");
  }
  const DfsphBounds bounds = dfsph_solve_bounds(fluid.methods.dfsph, divergence, dt);
  struct Passes {
    const FluidConstants& fluid;
    const GridView& grid;
    const ParticleArrays& a;
    uint32_t n;
    Float4* v;
    const float* warm;
    float* carried;
    bool divergence, contacts;
    DfsphBounds bounds;
    uint32_t min_iterations, max_iterations;
    DfsphRankSteps& rank;
    FrameState* state;
    cudaStream_t stream;
    void velocity_update(bool first) {
      launch_dfsph_correct(first, fluid, grid, a, n, v, first ? warm : a.dfsph_step, carried, divergence,
                           contacts, state, stream);
    }
    void share_velocities() { rank.share_velocities(v, stream); }
    void rates() {
      unsigned long long* bins = rank.error_bins();
      cuda_check(cudaMemsetAsync(bins, 0, sizeof(unsigned long long) * kDfsphRankErrorWords, stream),
                 "DFSPH error bins reset");
      launch_dfsph_rank_residual(divergence, fluid, grid, a, n, v, bins, state, stream);
    }
    void share_steps() { rank.share_steps(stream); }
    DfsphErrors errors() { return rank.errors(divergence, stream); }
    void checked(uint32_t iterations, const DfsphErrors& errors, bool) {
      dfsph_rank_check_kernel<<<1, 1, 0, stream>>>(
          iterations, errors, bounds, min_iterations, max_iterations, divergence,
          chebyshev_density_solve(fluid.methods.dfsph, divergence), state);
      check_launch("dfsph_rank_check_kernel");
    }
  } passes{fluid,          grid,           a,    n,     v,     warm, carried, divergence, contacts, bounds,
           min_iterations, max_iterations, rank, state, stream};
  run_dfsph_jacobi(passes, bounds, min_iterations, max_iterations);
}

}  // namespace sph
