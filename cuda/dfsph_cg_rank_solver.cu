// SPDX-License-Identifier: MIT
// DFSPH's density solve by conjugate gradients on a distributed rank (include/sph_mpi.h): the host
// drives it as the CPU rank's loop (src/cpu/cpu_dfsph_cg.cpp), the ghosts taking their owners'
// search directions and velocity steps within each iteration (DfsphRankSteps, cuda_halo.cu).
// Each kernel below adds the terms of the rank's own particles (not its ghosts) into the exact
// sums' bins (dfsph_solver.h's kDfsphRankCgWords layout: sum s at word s kTerms, the maxima from
// kDfsphRankCgMaxima), which the host adds over the ranks (DfsphRankSteps::cg_world). A particle's
// share of each sum is the undivided solve's (dfsph_cg_common.cuh), and so are the particle
// kernels without sums (the direction, the update, the next direction: dfsph_cg_solver.cu), the
// host writing alpha, beta and the flags they read (cg_rank_set_kernel).
//
// The neighbour passes walk the rank's own particles only, as the CPU rank's (b576397): a ghost's
// p and dv_p are its owner's, shared before each use (above), and what a ghost's own walks gave
// (its value, its change, its held changes' rate, its z) fed only its own search direction, which
// its owner's replaces before any use; so a ghost's value, change and z are written 0 and its
// neighbours are never walked. Everything else a ghost holds follows from the shared values as its
// owner's does: its velocity, its carried pressure and its contact holds (made in cg_update_kernel
// from its own velocity, and read by its neighbours' held-change gathers, as its owner's hold is on
// the owner's rank). The walks use the density pass's candidate masks (or the neighbour lists
// written from them), as the undivided solve's; that pass leaves a ghost's empty
// (dfsph_density.cu), which no pass of this solve reads.
#include "dfsph_cg_common.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

__device__ bool cg_own(const CgSolve& s, uint32_t i) {
  return i < s.n && !(s.a.halo_ghost && s.a.halo_ghost[i]);
}

constexpr uint32_t kCgTerms = ExactFloatSum::kTerms;

// After the warm start: each particle's value; the sum and largest of the errors.
__global__ void __launch_bounds__(kDfsphSolveBlock)
    cg_rank_measure_kernel(CgSolve s, unsigned long long* bins) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool own = cg_own(s, i);
  float error = 0.0f;
  if (own)
    error = cg_measure_particle(s, i);
  else if (i < s.n)
    s.a.dfsph_cg_value[i] = 0.0f;  // a ghost's (the file's top)
  exact_bins_add(bins, own, error);
  dfsph_block_max_to(bins + kDfsphRankCgMaxima, own ? error : 0.0f);
}

// A kernel of one sum over the set: a new cycle's value . p (cg_restart_particle) or the
// operator's p . A p (cg_change_particle).
enum class CgSetSum { Restart, Change };
template <CgSetSum kSum>
__global__ void __launch_bounds__(kDfsphSolveBlock)
    cg_rank_set_sum_kernel(CgSolve s, unsigned long long* bins) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool own = cg_own(s, i);
  CgTerm t{0.0f, false};
  if constexpr (kSum == CgSetSum::Restart) {
    if (i < s.n) t = cg_restart_particle(s, i);  // (no walk; a ghost's p is replaced before its use)
  } else if (own) {
    t = cg_change_particle(s, i);
  } else if (i < s.n) {
    s.a.dfsph_cg_change[i] = 0.0f;  // a ghost's (the file's top)
  }
  exact_bins_add(bins, own && t.active, t.value);
}

// The held contacts' changes added to the values (cg_held_value); the sums of the errors (sum 0),
// of those outside the set that a new set could take (sum 1) and, with z the Jacobi step over the
// set (into dfsph_residual), of value . z (sum 2, dropped by a restart); the largest error and the
// largest outside the set.
__global__ void __launch_bounds__(kDfsphSolveBlock)
    cg_rank_error_kernel(CgSolve s, unsigned long long* bins) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool own = cg_own(s, i);
  float error = 0.0f;
  bool outside = false;
  CgTerm sz{0.0f, false};
  if (own) {
    const float value = cg_held_value(s, i);
    error = dfsph_cg_error(value, s.fluid.rest_density);
    sz = cg_residual_particle(s, i, value);
    outside = !sz.active && s.a.dfsph_factor[i] > 0.0f;
  } else if (i < s.n) {
    s.a.dfsph_residual[i] = 0.0f;  // a ghost's z: its next p is its owner's (the file's top)
  }
  exact_bins_add(bins, own, error);
  exact_bins_add(bins + kCgTerms, own && outside, error);
  exact_bins_add(bins + 2 * kCgTerms, own && sz.active, sz.value);
  dfsph_block_max_to(bins + kDfsphRankCgMaxima, own ? error : 0.0f);
  dfsph_block_max_to(bins + kDfsphRankCgMaxima + 1, own && outside ? error : 0.0f);
}

// The operator on p, first half: the velocities p would give, for the rank's own particles (a
// ghost's dv_p is its owner's, shared right after).
__global__ void __launch_bounds__(kDfsphSolveBlock) cg_rank_direction_kernel(CgSolve s) {
  if (s.state->solve_run == 0) return;  // (as the undivided solve's kernel)
  mark_stage(s.state, kStageForces);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  // A ghost writes 0: its owner's dv_p replaces it right after, except for a spring ghost (beyond
  // the density records' halo, which no share reaches and no owned particle's walk reads), which
  // keeps 0 rather than the last iteration's or substep's data.
  if (cg_own(s, i))
    cg_direction_particle(s, i);
  else if (i < s.n)
    s.a.dfsph_cg_velocity_step[i] = make_float4_record(Vec3{0.0f, 0.0f, 0.0f}, 0.0f);
}

// What the undivided solve's particle kernels read of the state: the step, the next direction's
// beta, no skip, no contact held yet. One thread.
__global__ void cg_rank_set_kernel(FrameState* state, float alpha, float beta) {
  state->cg_alpha = alpha;
  state->cg_beta = beta;
  state->cg_skip = 0;
  state->cg_held = 0;
}

// The solve's record, as the undivided solve's check kernels leave it. One thread.
__global__ void cg_rank_record_kernel(FrameState* state, uint32_t iterations, DfsphErrors errors,
                                      DfsphBounds bounds) {
  state->solve_iterations = iterations;
  state->solve_error = errors.mean;
  state->solve_largest = errors.largest;
  dfsph_stop_solve(state, state->pressure_tally, bounds, LoopCondition{});
}

}  // namespace

void enqueue_dfsph_cg_rank_solve(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                                 uint32_t n, bool contacts, DfsphRankSteps& rank, FrameState* state,
                                 cudaStream_t stream) {
  if (!a.dfsph_cg_value || !a.dfsph_residual)
    throw Error(Status::Internal, "DFSPH's conjugate gradients: the world has no arrays for them");
  const Dfsph::Constants& c = fluid.methods.dfsph;
  const DfsphBounds bounds = dfsph_density_bounds(c);
  const unsigned threads = kDfsphSolveBlock, blocks = blocks_for(n, threads);
  const CgSolve s{fluid, grid, a, n, contacts, blocks, LoopCondition{}, state, nullptr};
  unsigned long long* bins = rank.error_bins();
  // A kernel that adds into the bins, after they are cleared.
  auto summed = [&](void (*kernel)(CgSolve, unsigned long long*), const char* name) {
    cuda_check(cudaMemsetAsync(bins, 0, sizeof(unsigned long long) * kDfsphRankCgWords, stream),
               "DFSPH conjugate gradients' bins reset");
    kernel<<<blocks, threads, 0, stream>>>(s, bins);
    check_launch(name);
  };
  auto particles = [&](void (*kernel)(CgSolve), const char* name) {
    kernel<<<blocks, threads, 0, stream>>>(s);
    check_launch(name);
  };
  auto set = [&](float alpha, float beta) {
    cg_rank_set_kernel<<<1, 1, 0, stream>>>(state, alpha, beta);
    check_launch("cg_rank_set_kernel");
  };
  double sums[3] = {0.0, 0.0, 0.0};
  float maxima[2] = {0.0f, 0.0f};
  summed(cg_rank_measure_kernel, "cg_rank_measure_kernel");
  const int64_t count = rank.cg_world(1, sums, 1, maxima, stream);
  const double particles_in_world = static_cast<double>(count);
  DfsphErrors error{count > 0 ? static_cast<float>(sums[0] / particles_in_world) : 0.0f, maxima[0]};
  uint32_t iterations = 0;
  bool restart = true;
  double sz = 0.0;  // value . z over the active set
  float alpha = 0.0f;
  while ((dfsph_bounds_unmet(bounds, error) || iterations < Dfsph::kMinIterations) &&
         iterations < c.max_iterations) {
    if (restart) {
      summed(cg_rank_set_sum_kernel<CgSetSum::Restart>, "cg_rank_restart_kernel");
      rank.cg_world(1, sums, 0, nullptr, stream);
      sz = sums[0];
      restart = false;
      if (sz == 0.0 && iterations >= Dfsph::kMinIterations) break;
    }
    // The operator on p: the ghosts' p before the velocities it gives, their dv_p before the rates.
    rank.share_steps(stream);
    particles(cg_rank_direction_kernel, "cg_rank_direction_kernel");
    rank.share_velocities(a.dfsph_cg_velocity_step, stream);
    summed(cg_rank_set_sum_kernel<CgSetSum::Change>, "cg_rank_change_kernel");
    rank.cg_world(1, sums, 0, nullptr, stream);
    const double pq = sums[0];
    ++iterations;
    if (!(pq > 0.0)) {  // no descent left along p (rounding): a new cycle from the same state
      restart = true;
      continue;
    }
    alpha = static_cast<float>(sz / pq);
    set(alpha, 0.0f);
    particles(cg_update_kernel, "cg_update_kernel");
    summed(cg_rank_error_kernel, "cg_rank_error_kernel");
    rank.cg_world(3, sums, 2, maxima, stream);
    error = {static_cast<float>(sums[0] / particles_in_world), maxima[0]};
    if (dfsph_cg_restart_due(bounds, sums[1] / particles_in_world, maxima[1])) {
      restart = true;
      continue;
    }
    const float beta = static_cast<float>(sums[2] / sz);
    sz = sums[2];
    set(alpha, beta);
    particles(cg_next_direction_kernel, "cg_next_direction_kernel");
  }
  cg_rank_record_kernel<<<1, 1, 0, stream>>>(state, iterations, error, bounds);
  check_launch("cg_rank_record_kernel");
  cg_keep_kernel<<<blocks, threads, 0, stream>>>(a.dfsph_pressure, n);
  check_launch("cg_keep_kernel");
}

}  // namespace sph
