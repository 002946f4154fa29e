// SPDX-License-Identifier: MIT
// DFSPH's density pass on the CUDA backend (dfsph_solver.h): each particle's density, neighbour
// count and factor in one walk that also records the solves' candidate masks and neighbour lists,
// the warm starts, the walls' share and contacts; the solves and the step are dfsph_solver.cu's.
#include "../src/physics/collider_loads.h"
#include "../src/physics/dfsph_passes.h"
#include "dfsph_clamp.cuh"
#include "dfsph_solver.h"
#include "force_gather.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

// The warm starts' pressures in the sorted order, as the CPU backend's solves compute them
// (k = share * carried / scale), from the carried values in the state order: particle i's old
// index is the w the reorder left in its sorted record.
__device__ __forceinline__ void dfsph_sort_warm_starts(const ParticleArrays& a, uint32_t i, uint32_t old,
                                                       float dt) {
  a.dfsph_step[i] = Dfsph::kWarmStart * a.dfsph_divergence[old] / dt;
  a.dfsph_warm_pressure[i] = Dfsph::kWarmStart * a.dfsph_pressure[old] / 1.0f;
}

// Before a density pass that carries the divergence solve's warm start: every particle's warm
// pressures sorted first, since that pass reads its neighbours'.
__global__ void dfsph_warm_starts_kernel(ParticleArrays a, uint32_t n, FrameState* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  dfsph_sort_warm_starts(a, i, __float_as_uint(a.sorted_position[i].w), state->clock.dt_float);
}

// One particle of the density pass. kBoundary: SPH_FEATURE_BOUNDARY_DENSITY, the walls' share
// (dfsph_boundary.h, place 1) at the substep's start, its record kept for the solves.
// kDivergenceWarmStart: the divergence solve's warm start rides in this walk
// (dfsph_divergence_warm_start_in_density_pass): its velocity change, -dt sum_j m (k_i + k_j)
// grad W_ij (pressure_velocity_change's sum, term for term, in the same order: the walk visits the
// solves' candidates in their order), needs only the positions and the sorted warm pressures
// (dfsph_warm_starts_kernel, before this pass), so the solve's own first pass is not run; the
// velocity is held to the contact and the impulse carried as dfsph_correct_kernel<true, false>
// would: the same arithmetic, so the same bits, and one neighbour pass a substep less (session 37).
template <bool kBoundary, bool kDivergenceWarmStart>
__device__ __forceinline__ void dfsph_density_particle(const FluidConstants& fluid, const GridView& grid,
                                                       const ParticleArrays& a, uint32_t n,
                                                       const DeviceScene& scene, FrameState* state) {
  mark_stage(state, kStageDensity);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  // The reorder left this particle's old index in w; the carried pressures are still in the
  // old order (nothing writes them in this kernel, unless the warm starts were sorted before it),
  // their sorted copies go to scratch arrays.
  const Float4 p = a.sorted_position[i];
  const uint32_t k = __float_as_uint(p.w);
  const float dt = state->clock.dt_float;
  BoundaryShare wall = no_boundary_share();
  if (kBoundary) {
    const StageTime at = stage_time(state->clock.time, 0.0f);
    wall =
        boundary_share(fluid.methods.boundary, scene.colliders, scene.collider_count, xyz(p), at.s, at.tau);
    a.boundary_gradient[i] = pack_boundary(wall);
  }
  // The candidate masks of the solves' passes and, with lists, the neighbour lists, recorded by
  // this walk (the positions are the substep's until the solves end).
  // (The same code without masks: a null writer stores nothing; see NeighborMaskWriter.)
  uint32_t* const mask =
      a.dfsph_neighbor_mask ? a.dfsph_neighbor_mask + static_cast<size_t>(i) * kNeighborMaskWords : nullptr;
  const NeighborMaskWriter writer{mask, mask ? a.dfsph_neighbor_list : nullptr, a.dfsph_list_stride, i};
  const KernelCoefficients mk = mass_gradient_kernel(fluid);
  const float ki = kDivergenceWarmStart ? a.dfsph_step[i] : 0.0f;
  Vec3 push{0.0f, 0.0f, 0.0f};
  // A distributed rank's ghost skips its walk: its density, factor, count and 1 / rho are its
  // owner's, taken right after this pass (HaloDfsphDensityRecord), and no pass walks a ghost's
  // candidates (dfsph_solver.cu; the conjugate gradients' rank solve, dfsph_cg_rank_solver.cu, since
  // session 41), so its mask and list are written empty. The moves below (the velocity, the warm
  // starts, the contact) stay: the records do not carry them.
  DfsphDensitySample s;
  if (is_halo_ghost(a, i)) {
    writer.finish();
    s = DfsphDensitySample{fluid.rest_density, 0u, 0.0f};
  } else {
    s = kDivergenceWarmStart ? gather_density_and_factor(fluid, grid, a.sorted_position, wall, i, writer,
                                                         [&](uint32_t j, Vec3 d, float r2) {
                                                           push += pressure_velocity_pair_term(
                                                               mk, d, r2, ki + a.dfsph_step[j]);
                                                         })
                             : gather_density_and_factor(fluid, grid, a.sorted_position, wall, i, writer);
  }
  a.density[i] = s.density;
  a.neighbor_count[i] = s.neighbor_count;
  a.dfsph_factor[i] = s.factor;
  if (!kDivergenceWarmStart) dfsph_sort_warm_starts(a, i, k, dt);
  const bool contacts = scene.collider_count != 0;
  if (contacts) {
    uint32_t collider = scene.collider_count;
    a.dfsph_contact[i] = wall_contact(scene.colliders, scene.collider_count, state->clock.time,
                                      scene.kernel_radius, xyz(p), collider);
    // With the loads, the clamp's impulses start at zero, named after the contact's collider.
    if (a.dfsph_contact_impulse) a.dfsph_contact_impulse[i] = no_clamp(collider);
  }
  a.sorted_position[i].w = 0.0f;  // no equation of state: the pressure is written after the solves
  Vec3 v = xyz(a.velocity[k]);
  if (kDivergenceWarmStart) {
    v += dfsph_velocity_change(push, DfsphWalls{a.boundary_gradient}, i, ki, dt);
    if (contacts) v = dfsph_clamp(a, i, v);
    a.dfsph_divergence[i] = 0.0f + ki * dt;  // (the warm pass's carried impulse, -0 included)
  }
  a.sorted_velocity[i] = make_float4_record(v, 1.0f / s.density);
}

// The pass without the walls' share, held to 72 registers: ptxas gives it 109 uncapped, which
// leaves room for 4 blocks of 128 threads an SM; at 72 (no spills, ptxas -v) 7 fit, and the
// gather hides more of its memory latency. Measured in the million-particle dam break on an H100
// (session 33, one call, the cap then on the whole template; the same printed results): the
// density stage 0.972 -> 0.798 ms a substep with the neighbour lists, 0.841 -> 0.587 with the
// masks; the whole run 2.9 / 3.4 % less wall time (docs/performance.md, "Session 33").
template <bool kDivergenceWarmStart>
__global__ void __maxnreg__(72) dfsph_density_kernel(FluidConstants fluid, GridView grid, ParticleArrays a,
                                                     uint32_t n, DeviceScene scene, FrameState* state) {
  dfsph_density_particle<false, kDivergenceWarmStart>(fluid, grid, a, n, scene, state);
}
// With the walls' share (uncapped: at 72 registers it spills 220 bytes, not measured).
template <bool kDivergenceWarmStart>
__global__ void dfsph_density_walls_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                           DeviceScene scene, FrameState* state) {
  dfsph_density_particle<true, kDivergenceWarmStart>(fluid, grid, a, n, scene, state);
}

}  // namespace

void enqueue_dfsph_density(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                           uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                           const DeviceScene& scene, bool divergence_warm_start, FrameState* state,
                           cudaStream_t stream) {
  const unsigned threads = tuning.density_block;
  if (divergence_warm_start) {
    const unsigned t = fit_block(dfsph_warm_starts_kernel, threads);
    dfsph_warm_starts_kernel<<<blocks_for(n, t), t, 0, stream>>>(a, n, state);
    check_launch("dfsph_warm_starts_kernel");
  }
  const auto launch = [&](auto kernel) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, grid, a, n, scene, state);
    check_launch("dfsph_density_kernel");
  };
  if (options.boundary_density)
    launch(divergence_warm_start ? dfsph_density_walls_kernel<true> : dfsph_density_walls_kernel<false>);
  else
    launch(divergence_warm_start ? dfsph_density_kernel<true> : dfsph_density_kernel<false>);
}

}  // namespace sph
