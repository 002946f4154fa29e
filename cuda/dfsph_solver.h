// SPDX-License-Identifier: MIT
// DFSPH on the device (physics/dfsph.h; the twin of src/cpu/cpu_dfsph_solver.cpp): the density
// and factor pass, then the divergence solve, the non-pressure accelerations, the density solve
// and the step. Each solve is a Jacobi loop (or, for the density solve, conjugate gradients:
// dfsph_cg_solver.cu) of three kernels, the velocity update, the new rates
// and pressures (with each block's error sum in a fixed tree) and a one-block convergence check
// (the block sums in a fixed order) that decides whether the loop goes on, so the iteration
// counts and every result are the same bits on every run. The loop never waits for the host per
// iteration: in the frame graph it is a conditional WHILE node nested in the substep's, whose
// condition the check kernel sets; on the stream (the stream driver) the kernels run in chunks of
// kSolveChunk iterations, each of which does nothing once the check has stopped the solve, and the
// host reads the flag once per chunk.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/exact_float_sum.h"
#include "../src/physics/dfsph.h"
#include "../src/physics/fluid_constants.h"
#include "../src/physics/neighbor_walk.h"
#include "device_particle_store.h"
#include "frame_control.h"
#include "frame_state.cuh"
#include "substep_kernels.h"

namespace sph {

// Threads per block of the residual kernel: fixed, since its block sums are the reduction's
// tree (the tuning knobs must not change results).
constexpr unsigned kDfsphSolveBlock = 128;
// Iterations the stream driver launches between two reads of the convergence flag.
constexpr uint32_t kDfsphSolveChunk = 4;

// Doubles the solves' block sums need for `capacity` particles: two per block (the conjugate
// gradients' error pass sums two quantities).
inline uint32_t dfsph_partial_count(uint32_t capacity) {
  return 2u * (capacity == 0 ? 1u : (capacity + kDfsphSolveBlock - 1) / kDfsphSolveBlock);
}

// Whether the divergence solve's warm start rides in the density pass (enqueue_dfsph_density's
// divergence_warm_start; dfsph_density.cu): with the divergence solve on, in the undivided world (a
// rank's solves start with the ghosts' exchanges), with the plain gradient (the corrected velocity
// update gathers a moment too), and without springs (their pass, between the density pass and the
// solve, reads the sorted velocities that the warm start changes). `rank`: a distributed rank's step.
inline bool dfsph_divergence_warm_start_in_density_pass(const FluidConstants& fluid,
                                                        const SubstepOptions& options, bool rank) {
  return fluid.methods.dfsph.divergence_solve != 0 && !rank && fluid.methods.dfsph.gradient_correction == 0 &&
         !options.springs;
}

// DFSPH's density pass: rho_i, the neighbour counts, the factor, the candidate masks and neighbour
// lists where the world keeps them, each particle's contact with the colliders, the warm starts gathered from
// the state order into the sorted order, and the sorted velocities (w: 1 / rho). With
// divergence_warm_start (dfsph_divergence_warm_start_in_density_pass) the sorted velocities have the
// divergence solve's warm start applied, and its impulses are carried. (The colour normals, with
// surface tension, come after it: substep_pipeline.cu, where a distributed rank's ghosts first take their
// owners' densities.)
void enqueue_dfsph_density(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                           uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                           const DeviceScene& scene, bool divergence_warm_start, FrameState* state,
                           cudaStream_t stream);

// A distributed rank's host steps inside DFSPH's solves (cuda_halo.cu; the stream driver only):
// the host drives each Jacobi solve, an iteration at a time, by core/dfsph_jacobi_loop.h (the CPU
// rank's loop), which says when the ghosts take their owners' velocities and pressure steps k
// and reads the world's mean error.
// A distributed rank's error words: the exact sum's bins, then the largest error's float bits.
constexpr uint32_t kDfsphRankErrorWords = ExactFloatSum::kTerms + 1;
// The conjugate gradients' (dfsph_cg_solver.cu) in the same buffer: up to three exact sums' bins
// (sum s at word s kTerms), then up to two maxima's float bits from word kDfsphRankCgMaxima.
constexpr uint32_t kDfsphRankCgMaxima = 3 * ExactFloatSum::kTerms;
constexpr uint32_t kDfsphRankCgWords = kDfsphRankCgMaxima + 2;

struct DfsphRankSteps {
  virtual ~DfsphRankSteps() = default;
  // The ghosts take their owners' velocities of v (the solve's velocities, sorted order).
  virtual void share_velocities(Float4* v, cudaStream_t stream) = 0;
  // The ghosts take their owners' pressure steps k (ParticleArrays::dfsph_step).
  virtual void share_steps(cudaStream_t stream) = 0;
  // kDfsphRankErrorWords device words: ExactFloatSum::kTerms bins (int64 in two's complement), into
  // which the rate pass adds the errors of the rank's own particles, then the float bits of the
  // largest of them (the density solve's; atomicMax).
  virtual unsigned long long* error_bins() = 0;
  // The world's errors: the mean, the bins (after the rate pass) added over the ranks, over the
  // world's particle count; the largest, the ranks' largest (the density solve's; 0 for the
  // divergence solve, with no reduction). Waits for the stream.
  virtual DfsphErrors errors(bool divergence, cudaStream_t stream) = 0;
  // The conjugate gradients' sums and maxima: error_bins() holds kDfsphRankCgWords words, `sums`
  // exact sums' bins and `maxima` maxima (the layout above) of the rank's own particles; the
  // world's sums (the bins added over the ranks, as doubles) into values, its maxima (the ranks'
  // largest) into largest; returns the world's particle count. Waits for the stream.
  virtual int64_t cg_world(int sums, double* values, int maxima, float* largest, cudaStream_t stream) = 0;
};

// Where a solve's loop runs and what it needs beyond the particles.
struct DfsphLoops {
  bool in_graph;                   // capturing a substep into the frame graph
  double* partials;                // dfsph_partial_count(capacity) doubles
  FrameState* host_state;          // pinned: the stream driver reads solve_run here
  DfsphRankSteps* rank = nullptr;  // a distributed rank's (the host drives the loop); null otherwise
};

// The density solve by conjugate gradients (sph_dfsph_params.linear_solver =
// SPH_DFSPH_CONJUGATE_GRADIENTS; dfsph_cg_solver.cu), after the warm start's velocity update:
// the initial values and check, the loop on `cond` (open_solve_loop), the kept pressures.
void enqueue_dfsph_cg_solve(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                            uint32_t n, bool contacts, const DfsphLoops& loops, const LoopCondition& cond,
                            FrameState* state, cudaStream_t stream);
// The same on a distributed rank (dfsph_cg_rank_solver.cu), after the warm start's velocity
// update and the ghosts' taking their owners' velocities: the host drives it as the CPU rank's
// loop (src/cpu/cpu_dfsph_cg.cpp), the ghosts taking their owners' search directions and velocity
// steps in each iteration, the sums exact and added over the ranks (rank.cg_world), the solve's
// record written at its end.
void enqueue_dfsph_cg_rank_solve(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                                 uint32_t n, bool contacts, DfsphRankSteps& rank, FrameState* state,
                                 cudaStream_t stream);

// A Jacobi solve (either solve) on a distributed rank (dfsph_jacobi_rank_solver.cu): the host
// drives it as the CPU rank's loop (core/dfsph_jacobi_loop.h), from the warm start's velocity
// update to the solve's record; v, warm and carried are the solve's arrays, as enqueue_solve
// (dfsph_solver.cu) chooses them.
void enqueue_dfsph_jacobi_rank_solve(const FluidConstants& fluid, const GridView& grid,
                                     const ParticleArrays& a, uint32_t n, Float4* v, const float* warm,
                                     float* carried, bool divergence, bool contacts, uint32_t min_iterations,
                                     uint32_t max_iterations, DfsphRankSteps& rank, FrameState* state,
                                     cudaStream_t stream);

// The solves' passes that the rank solves launch (dfsph_solver.cu). The velocity update: v += the
// pressures k's velocity change (held to the contacts), and carried gets k times the solve's
// scale (dt for the divergence solve's impulse), replacing the carried values on the warm start's
// pass (`warm`) or added on an iteration's, with the gradient the world's parameters choose. Blocks
// of kDfsphSolveBlock threads, the only size the kernel's launch bounds admit.
void launch_dfsph_correct(bool warm, const FluidConstants& fluid, const GridView& grid,
                          const ParticleArrays& a, uint32_t n, Float4* v, const float* k, float* carried,
                          bool divergence, bool contacts, FrameState* state, cudaStream_t stream);
// The rates over v, the new pressure steps and the errors of the rank's own particles (not its
// ghosts) into the exact sum's bins (kDfsphRankErrorWords words), with the largest error's bits
// for the density solve (blocks of kDfsphSolveBlock threads, the block sums' fixed tree).
void launch_dfsph_rank_residual(bool divergence, const FluidConstants& fluid, const GridView& grid,
                                const ParticleArrays& a, uint32_t n, const Float4* v,
                                unsigned long long* bins, FrameState* state, cudaStream_t stream);

// After the density pass (and the spring pass): the divergence solve (unless skipped), the
// non-pressure accelerations, the density solve, positions, colliders and the reductions of the
// step's end (max speed, max acceleration, the non-finite check), into the state arrays; the
// pressure both solves applied also into the sorted records' w (the probes' and the loads' p).
// collide_here false (the loads on): the collision response and the max speed are left to the
// loads pass (enqueue_loads), which also gives the contact clamp's impulses to the colliders.
void enqueue_dfsph_step(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                        uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                        const DeviceScene& scene, const DfsphLoops& loops, bool collide_here,
                        FrameState* state, cudaStream_t stream);

}  // namespace sph
