// SPDX-License-Identifier: MIT
#include <type_traits>

#include "../src/core/exact_float_sum.h"
#include "../src/physics/collider_loads.h"
#include "../src/physics/dfsph_chebyshev.h"
#include "../src/physics/dfsph_passes.h"
#include "block_reduce.cuh"
#include "dfsph_clamp.cuh"
#include "dfsph_solve_loop.cuh"
#include "dfsph_solver.h"
#include "force_gather.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

// The solves' two passes (the velocity update and the residual), run once each a solve iteration
// (and for the warm start and the first residual), are bound by the latency of their neighbours'
// gathers (ncu, session 27: 26-29 cycles an issued instruction, memory throughput 43-66 %), so
// they are given 16 blocks of 128 threads an SM, all of an sm_90 SM's 2,048 threads (an SM with
// fewer runs fewer blocks; the cap still holds), which holds them to 32 registers (ptxas -v, sm_90:
// 46 and 47 before, 10 blocks; 48-56 bytes of spills a thread now). Measured on an H200 in
// session 34 (one machine, the 1M dam break at 0.1 % with the Chebyshev solve; docs/performance.md,
// "Session 34"): with the neighbour lists 56.93 / 56.84 s a simulated second -> 52.89 / 52.92 at 12
// blocks (40 registers) -> 49.08 at 16, the force stage 4.72 -> 3.95 ms a substep; with the masks
// (the default) 71.44 -> 70.66 / 70.76; the same printed results in every run. The corrected
// gradient's velocity update (54 registers, which would spill 104 bytes at 32; not timed) keeps its
// 9 blocks. Every launch of these kernels uses kDfsphSolveBlock threads.
constexpr int kDfsphSolveBlocksPerSm = 16;
constexpr int kDfsphCorrectedBlocksPerSm = 9;

__global__ void dfsph_begin_solve_kernel(FrameState* state) {
  state->solve_run = 1;
  state->solve_iterations = 0;
  state->solve_largest = 0.0f;
  state->solve_largest_bits = 0u;
  state->solve_weight = chebyshev_weight(0);
  state->solve_smallest = 0.0f;
  state->solve_plain = 0u;
}

// v += the pressures k's velocity change (held to the contacts); carried gets k times the
// solve's scale (dt for the divergence solve's impulse), added, or replacing the state-order
// values on the warm start's pass.
// kRank: a distributed rank's world (its ghosts skipped), its own instantiation so that the
// undivided world's kernel keeps its registers (the ghost test cost the 32-register form 20 bytes
// more of spills, ptxas -v, sm_90).
template <bool kWarm, bool kCorrected, bool kRank>
__global__ void __launch_bounds__(kDfsphSolveBlock,
                                  kCorrected ? kDfsphCorrectedBlocksPerSm : kDfsphSolveBlocksPerSm)
    dfsph_correct_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n, Float4* v,
                         const float* k, float* carried, bool divergence, bool contacts, FrameState* state) {
  if (state->solve_run == 0) return;
  mark_stage(state, kStageForces);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float dt = state->clock.dt_float;
  const float scale = divergence ? dt : 1.0f;
  if (kRank && a.halo_ghost[i]) {
    // A distributed rank's ghost: its velocity is its owner's, taken right after this pass
    // (core/dfsph_jacobi_loop.h, and the conjugate gradients' warm start), so no walk; its carried
    // pressure adds its owner's steps (shared before each use) as the owner's does, so that its
    // pressure, which the probes read, is the owner's. (A return of its own rather than a branch
    // around the walk: the rank's instantiation then spills 40 / 36 bytes, not 52 / 48; ptxas -v.)
    carried[i] = (kWarm ? 0.0f : carried[i]) + k[i] * scale;
    return;
  }
  // kCorrected: SPH_DFSPH_CORRECTED_GRADIENT (physics/dfsph_gradient_correction.h), its own
  // instantiation so that the default kernel keeps its registers.
  const DfsphWalls walls{a.boundary_gradient};
  const ListedCandidates walk = solve_walk(a);
  Vec3 vi = xyz(v[i]);
  vi += pressure_velocity_change<kCorrected>(fluid, grid, a.sorted_position, k, walls, i, dt, walk);
  if (contacts) vi = dfsph_clamp(a, i, vi);
  v[i] = make_float4_record(vi, v[i].w);
  carried[i] = (kWarm ? 0.0f : carried[i]) + k[i] * scale;
}

// New pressures from the rates over v; each block's error sum to partials[block], or (kExact, a
// distributed rank) the errors of the rank's own particles into the exact sum's bins.
template <bool kDivergence, bool kExact>
__global__ void __launch_bounds__(kDfsphSolveBlock, kDfsphSolveBlocksPerSm)
    dfsph_residual_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n, const Float4* v,
                          double* partials, unsigned long long* bins, FrameState* state) {
  if (state->solve_run == 0) return;  // the same for every thread of the grid
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  double error = 0.0;
  // (A distributed rank's ghost, kExact, takes its owner's k right after this pass and adds no error.)
  if (i < n && !(kExact && a.halo_ghost[i])) {
    const float dt = state->clock.dt_float;
    const float rate =
        density_rate(fluid, grid, a.sorted_position, v, DfsphWalls{a.boundary_gradient}, i, solve_walk(a));
    if (chebyshev_density_solve(fluid.methods.dfsph, kDivergence)) {
      // SPH_DFSPH_CHEBYSHEV (dfsph_chebyshev.h), as the CPU backend's: the pressure held so far is the
      // carried one, which every velocity update of this solve has added its steps to.
      const DfsphResidual r = chebyshev_density_residual(
          rate, a.density[i], a.dfsph_factor[i], fluid.rest_density, dt, a.dfsph_pressure[i],
          DfsphChebyshevPass{state->solve_weight, state->solve_plain}, &a.dfsph_step[i]);
      a.dfsph_step[i] = r.k;
      error = r.error;
    } else {
      const DfsphResidual r =
          kDivergence ? divergence_residual(fluid.methods.dfsph, rate, a.neighbor_count[i], a.dfsph_factor[i],
                                            fluid.rest_density, dt)
                      : density_residual(rate, a.density[i], a.dfsph_factor[i], fluid.rest_density, dt);
      a.dfsph_step[i] = r.k;
      error = r.error;
    }
  }
  // (if constexpr: the undivided world's kernel keeps its code and its shared memory). The largest
  // error: the density solve's only (the divergence solve does not bound it).
  if constexpr (kExact) {
    const bool own = i < n && !(a.halo_ghost && a.halo_ghost[i]);
    exact_bins_add(bins, own, static_cast<float>(error));
    if (!kDivergence)
      dfsph_block_max_to(bins + ExactFloatSum::kTerms, own ? static_cast<float>(error) : 0.0f);
  } else {
    dfsph_block_sum_to(partials, error);
    if (!kDivergence) dfsph_block_max_to(&state->solve_largest_bits, static_cast<float>(error));
  }
}

// The solve's mean error from the block sums; whether it goes on; its record when it stops.
__global__ void __launch_bounds__(kDfsphCheckBlock)
    dfsph_check_kernel(const double* partials, uint32_t blocks, uint32_t n, Dfsph::Constants c,
                       uint32_t min_iterations, uint32_t max_iterations, bool divergence, bool first,
                       LoopCondition cond, FrameState* state) {
  if (state->solve_run == 0) return;
  // (Here, not on the host: the divergence bound depends on the substep's dt, chosen on the device.)
  const DfsphBounds bounds = dfsph_solve_bounds(c, divergence, state->clock.dt_float);
  const double sum = dfsph_sum_partials(partials, blocks);
  if (threadIdx.x != 0) return;
  state->solve_iterations = first ? 0u : state->solve_iterations + 1u;
  state->solve_error = n > 0 ? static_cast<float>(sum / n) : 0.0f;
  if (chebyshev_density_solve(c, divergence))
    dfsph_chebyshev_after_test(state, state->solve_iterations, state->solve_error, bounds.mean);
  dfsph_take_largest(state);
  dfsph_continue_solve(state, divergence ? state->divergence_tally : state->pressure_tally, bounds,
                       min_iterations, max_iterations, cond);
}

// v* = v + dt a with the non-pressure accelerations, into the state's velocity array (free
// since the density pass gathered it), held to the contacts. With `warm` (the density solve's warm
// pressures, a.dfsph_warm_pressure; null where the solve makes its own warm start: a distributed
// rank, the corrected gradient), the density solve's warm start runs here too: its velocity change
// (pressure_velocity_change's sum, term for term) is gathered in the same walk, since it reads only
// the positions and the warm pressures, both known before this pass; then applied and held to the
// contacts, and its pressures carried, as dfsph_correct_kernel<true, false> would in a pass of its
// own. The same arithmetic in the same order, so the same bits, and one neighbour pass a substep
// less (session 36).
template <class Terms, bool kScene>
__global__ void dfsph_forces_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                    DeviceScene scene, bool divergence_solve, const float* warm,
                                    FrameState* state) {
  mark_stage(state, kStageForces);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  float a2 = 0.0f;
  if (i < n && is_halo_ghost(a, i)) {
    // A distributed rank's ghost: its owner's acceleration counts, and its v* is replaced by its
    // owner's after the density solve's first velocity update, which reads no ghost's v* (nor
    // its divergence warm start: a rank's solves make their own).
    a.velocity[i] = a.sorted_velocity[i];
    if (!divergence_solve) a.dfsph_divergence[i] = 0.0f;
  } else if (i < n) {
    FluidConstants f = fluid;
    f.dt = state->clock.dt_float;
    // Over the solves' walk (the lists, the masks, or every candidate), one body for all three,
    // so that they give the same bits (neighbor_walk.h); each pair tested and summed with one r^2.
    // (gather_acceleration_masked, the weakly compressible pass's two-phase walk, computes r^2 once
    // to test and again for the term.)
    AccelerationGather<Terms, false> gather(
        ForceInputs{a.sorted_position, a.sorted_velocity, a.neighbor_count, a.colour_normal}, i);
    const Vec3 xi = gather.position();
    const KernelCoefficients mk = mass_gradient_kernel(fluid);
    const float ki = warm ? warm[i] : 0.0f;
    Vec3 push{0.0f, 0.0f, 0.0f};
    solve_walk(a)(grid, xi, i, [&](uint32_t j) {
      const Float4 pj = a.sorted_position[j];
      const Vec3 d = xi - xyz(pj);
      const float r2 = length_squared(d);
      if (!is_force_neighbor(f, r2, i, j)) return;
      gather.add(f, j, pj, d, r2);
      if (warm) push += pressure_velocity_pair_term(mk, d, r2, ki + warm[j]);
    });
    Vec3 acc = gather.finish(f);
    const Float4 p = a.sorted_position[i];
    const Float4 v = a.sorted_velocity[i];
    if (kScene) acc = add_force_fields(scene, acc, xyz(p));
    if (a.spring_acceleration) acc += xyz(a.spring_acceleration[i]);
    a2 = length_squared(acc);
    Vec3 next = xyz(v) + acc * f.dt;
    const bool contacts = scene.collider_count != 0;
    if (kScene && contacts) next = dfsph_clamp(a, i, next);
    if (warm) {
      next += dfsph_velocity_change(push, DfsphWalls{a.boundary_gradient}, i, ki, f.dt);
      if (contacts) next = dfsph_clamp(a, i, next);
      a.dfsph_pressure[i] = 0.0f + ki * 1.0f;  // (the warm pass's carried value, -0 included)
    }
    a.velocity[i] = make_float4_record(next, v.w);
    if (!divergence_solve) a.dfsph_divergence[i] = 0.0f;  // no warm start to keep
  }
  block_max_to(&state->a2max_bits, a2);
}

// x += dt v*, the colliders (unless the loads pass takes them: collide_here false), the pressure
// both solves applied (also into the sorted record's w, where the probes and the loads' walls read
// it), the state in the sorted order.
template <bool kScene>
__global__ void dfsph_integrate_kernel(ParticleArrays a, uint32_t n, DeviceScene scene, bool divergence_solve,
                                       bool collide_here, FrameState* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  float v2 = 0.0f;
  if (i < n) {
    const float dt = state->clock.dt_float;
    const Float4 p = a.sorted_position[i];
    const Float4 v = a.velocity[i];
    ParticleState next{xyz(p) + xyz(v) * dt, xyz(v)};
    if (kScene && collide_here) collide_all(scene, state->clock.time, xyz(p), next);
    const float rho = a.density[i];
    const float divergence = divergence_solve ? 1.0f / dt : 0.0f;
    const uint32_t id = a.sorted_id[i];
    const float pressure = dfsph_pressure(a.dfsph_pressure[i], a.dfsph_divergence[i] * divergence, rho);
    a.sorted_position[i].w = pressure;
    a.position[i] = make_float4_record(next.position, pressure);
    a.velocity[i] = make_float4_record(next.velocity, v.w);
    a.id[i] = id;
    v2 = length_squared(next.velocity);
    if (a.halo_ghost && a.halo_ghost[i])
      v2 = 0.0f;  // a distributed rank's ghost: its owner's to move
    else if (!state_finite(next.position, pressure, v2, v.w)) {
      // As the CPU backend: the solves count as the integration (no acceleration to blame), and the
      // record classified carries the pressure just computed (the CPU's holds it too), so a
      // non-finite pressure is the density stage's on both.
      flag_non_finite(state, 0, i, id,
                      classify_non_finite(rho, make_float4_record(xyz(p), pressure), a.sorted_velocity[i],
                                          Vec3{0.0f, 0.0f, 0.0f}, next));
      v2 = 0.0f;
    }
    if (!collide_here) v2 = 0.0f;  // the loads pass collides and takes the speed (device_collider_loads.h)
  }
  block_max_to(&state->v2max_bits, v2);
}

enum class Solve { Divergence, Density };

// One solve: the warm start's pass, the initial residual and check, then the loop.
// warm_started: another pass made the solve's warm start (the divergence solve's: the density
// pass, dfsph_density.cu; the density solve's: dfsph_forces_kernel's warm).
void enqueue_solve(Solve kind, const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                   uint32_t n, bool contacts, const DfsphLoops& loops, FrameState* state, cudaStream_t stream,
                   bool warm_started = false) {
  const bool divergence = kind == Solve::Divergence;
  const Dfsph::Constants& c = fluid.methods.dfsph;
  Float4* v = divergence ? a.sorted_velocity : a.velocity;
  float* carried = divergence ? a.dfsph_divergence : a.dfsph_pressure;
  const float* warm = divergence ? a.dfsph_step : a.dfsph_warm_pressure;
  const uint32_t min_iterations = divergence ? Dfsph::kMinDivergenceIterations : Dfsph::kMinIterations;
  const uint32_t max_iterations = divergence ? c.max_divergence_iterations : c.max_iterations;
  const unsigned threads = kDfsphSolveBlock, blocks = blocks_for(n, threads);
  const uint32_t partial_count = blocks;
  dfsph_begin_solve_kernel<<<1, 1, 0, stream>>>(state);
  check_launch("dfsph_begin_solve_kernel");
  const LoopCondition cond = open_solve_loop(loops.in_graph, stream);
  auto residual = [&] {
    if (divergence)
      dfsph_residual_kernel<true, false>
          <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, v, loops.partials, nullptr, state);
    else
      dfsph_residual_kernel<false, false>
          <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, v, loops.partials, nullptr, state);
    check_launch("dfsph_residual_kernel");
  };
  auto check = [&](bool first) {
    dfsph_check_kernel<<<1, kDfsphCheckBlock, 0, stream>>>(
        loops.partials, partial_count, n, c, min_iterations, max_iterations, divergence, first, cond, state);
    check_launch("dfsph_check_kernel");
  };
  if (loops.rank && !divergence && c.linear_solver == kDfsphConjugateGradients) {
    // A distributed rank's conjugate gradients: the warm start, the ghosts' velocities, then the
    // host-driven solve (dfsph_cg_rank_solver.cu, the CPU rank's loop).
    launch_dfsph_correct(true, fluid, grid, a, n, v, warm, carried, divergence, contacts, state, stream);
    loops.rank->share_velocities(v, stream);
    return enqueue_dfsph_cg_rank_solve(fluid, grid, a, n, contacts, *loops.rank, state, stream);
  }
  if (loops.rank)  // the host drives the loop (dfsph_jacobi_rank_solver.cu)
    return enqueue_dfsph_jacobi_rank_solve(fluid, grid, a, n, v, warm, carried, divergence, contacts,
                                           min_iterations, max_iterations, *loops.rank, state, stream);
  if (!warm_started)
    launch_dfsph_correct(true, fluid, grid, a, n, v, warm, carried, divergence, contacts, state, stream);
  // The same warm start (as the CPU backend's), then the conjugate gradients' iterations.
  if (!divergence && c.linear_solver == kDfsphConjugateGradients)
    return enqueue_dfsph_cg_solve(fluid, grid, a, n, contacts, loops, cond, state, stream);
  residual();
  check(true);
  run_solve_loop(cond, state, loops.host_state, stream, [&] {
    launch_dfsph_correct(false, fluid, grid, a, n, v, a.dfsph_step, carried, divergence, contacts, state,
                         stream);
    residual();
    check(false);
  });
}

}  // namespace

void launch_dfsph_correct(bool warm, const FluidConstants& fluid, const GridView& grid,
                          const ParticleArrays& a, uint32_t n, Float4* v, const float* k, float* carried,
                          bool divergence, bool contacts, FrameState* state, cudaStream_t stream) {
  const unsigned threads = kDfsphSolveBlock, blocks = blocks_for(n, threads);
  const bool corrected = fluid.methods.dfsph.gradient_correction != 0;
  const auto launch = [&](auto kernel) {
    kernel<<<blocks, threads, 0, stream>>>(fluid, grid, a, n, v, k, carried, divergence, contacts, state);
  };
  const auto on = [&](auto rank) {
    constexpr bool kRank = decltype(rank)::value;
    if (warm && corrected)
      launch(dfsph_correct_kernel<true, true, kRank>);
    else if (warm)
      launch(dfsph_correct_kernel<true, false, kRank>);
    else if (corrected)
      launch(dfsph_correct_kernel<false, true, kRank>);
    else
      launch(dfsph_correct_kernel<false, false, kRank>);
  };
  if (a.halo_ghost)  // a distributed rank's world (its ghost mask is allocated for ranks only)
    on(std::true_type{});
  else
    on(std::false_type{});
  check_launch("dfsph_correct_kernel");
}

void launch_dfsph_rank_residual(bool divergence, const FluidConstants& fluid, const GridView& grid,
                                const ParticleArrays& a, uint32_t n, const Float4* v,
                                unsigned long long* bins, FrameState* state, cudaStream_t stream) {
  const unsigned threads = kDfsphSolveBlock, blocks = blocks_for(n, threads);
  if (divergence)
    dfsph_residual_kernel<true, true>
        <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, v, nullptr, bins, state);
  else
    dfsph_residual_kernel<false, true>
        <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, v, nullptr, bins, state);
  check_launch("dfsph_residual_kernel");
}

void enqueue_dfsph_step(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                        uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                        const DeviceScene& scene, const DfsphLoops& loops, bool collide_here,
                        FrameState* state, cudaStream_t stream) {
  const bool contacts = scene.collider_count != 0;
  const bool divergence_solve = fluid.methods.dfsph.divergence_solve != 0;
  // The density pass made the divergence solve's warm start where the rule allows it (the same
  // rule there: substep_pipeline.cu).
  if (divergence_solve)
    enqueue_solve(Solve::Divergence, fluid, grid, a, n, contacts, loops, state, stream,
                  dfsph_divergence_warm_start_in_density_pass(fluid, options, loops.rank != nullptr));
  const unsigned threads = tuning.force_block;
  // The density solve's warm start in the forces pass, where the solve's own first pass would be
  // that warm start: not on a distributed rank (its solves start with the ghosts' exchanges) nor
  // with the corrected gradient (its velocity update gathers a moment too).
  const bool fused_warm_start = !loops.rank && fluid.methods.dfsph.gradient_correction == 0;
  const float* warm = fused_warm_start ? a.dfsph_warm_pressure : nullptr;
  const auto launch_forces = [&](auto kernel) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, grid, a, n, scene, divergence_solve, warm, state);
  };
  with_force_terms(options.methods, [&](auto terms) {
    using Terms = decltype(terms);
    if (scene.active())
      launch_forces(dfsph_forces_kernel<Terms, true>);
    else
      launch_forces(dfsph_forces_kernel<Terms, false>);
  });
  check_launch("dfsph_forces_kernel");
  enqueue_solve(Solve::Density, fluid, grid, a, n, contacts, loops, state, stream, fused_warm_start);
  const auto launch_integrate = [&](auto kernel) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for(n, t), t, 0, stream>>>(a, n, scene, divergence_solve, collide_here, state);
  };
  if (scene.active())
    launch_integrate(dfsph_integrate_kernel<true>);
  else
    launch_integrate(dfsph_integrate_kernel<false>);
  check_launch("dfsph_integrate_kernel");
}

}  // namespace sph
