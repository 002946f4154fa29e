// SPDX-License-Identifier: MIT
// The density pass's kernels (the summation over a lane group, the normalised density's filter,
// the density diffusion, the colour normals) and their launches: the first neighbour pass of a
// substep (substep_kernels.h). Compiled with the force pass's arithmetic flags (CMakeLists.txt).
#include "../src/physics/boundary_density.h"
#include "../src/physics/density.h"
#include "../src/physics/density_diffusion.h"
#include "../src/physics/density_normalization.h"
#include "../src/physics/surface_tension.h"
#include "force_gather.cuh"
#include "kernel_launch.h"
#include "lane_launch.cuh"
#include "substep_kernels.h"

namespace sph {
namespace {

using lanes::blocks_for_lanes;
using lanes::grid_thread;
using lanes::with_lanes;

// gather_density (src/physics/density.h) over a lane group: each lane sums every G-th candidate
// of a run, and the group adds the sums (LaneGroup). G = 1 is gather_density itself.
template <unsigned G>
__device__ __forceinline__ DensitySample gather_density_lanes(const FluidBase& f, const GridView& grid,
                                                              const Float4* __restrict__ positions,
                                                              uint32_t i, LaneGroup<G> group) {
  if (G == 1) return gather_density(f, grid, positions, i);
  const Vec3 xi = xyz(positions[i]);
  float sum = 0.0f;
  uint32_t neighbors = 0;
  for_each_neighbor_range(grid, xi, [&](uint32_t begin, uint32_t end) {
#pragma unroll 2
    for (uint32_t j = begin + group.lane; j < end; j += G) {
      const float r2 = length_squared(xi - xyz(positions[j]));
      if (r2 < f.kernel.h2 && j != i) {
        sum += density_pair_term(f, r2);
        ++neighbors;
      }
    }
  });
  return density_from_sum(f, group.sum(sum), group.sum(neighbors));
}

// With kNormalized the side array receives the kernel sum (for the filter's factor) or, with
// factor_to_side (the density diffusion, which has no filter), the resolved factor itself, so
// that a later kernel writes the factors in the new order without a division's rounding.
// G: the lane group (LaneGroup); lane 0 of each group writes the particle.
template <bool kCounts, bool kNormalized, bool kBoundary, unsigned G>
__global__ void density_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                               DeviceScene scene, float stage_fraction, bool factor_to_side,
                               FrameState* state) {
  mark_stage(state, kStageDensity);
  const unsigned long long t = grid_thread();
  if (t / G >= n) return;  // whole groups: n * G threads are lanes of particles
  const uint32_t i = static_cast<uint32_t>(t / G);
  const LaneGroup<G> group = LaneGroup<G>::of_thread(t);
  // A distributed rank's ghost (the whole lane group: one particle) skips its gather: its density,
  // pressure, 1 / density and count are its owner's, taken right after this pass
  // (HaloDensityRecord), before any pass reads them; ghost_density_moves_kernel moves the rest.
  // (A bare return: the undivided world's kernel keeps its registers, which a branch that wrote
  // the ghost here raised from 30 to 34 at two and four lanes, ptxas -v, sm_90.)
  if (is_halo_ghost(a, i)) return;
  DensitySample s = gather_density_lanes<G>(fluid, grid, a.sorted_position, i, group);
  if (group.lane != 0) return;
  // The reorder left this particle's old index in w; read it before w becomes the pressure.
  // Other threads read only x, y, z of this record.
  const uint32_t k = __float_as_uint(a.sorted_position[i].w);
  if (kBoundary) {
    // The walls' share is part of the summation (and so of a normalised density's kernel sum).
    const StageTime at = stage_time(state->clock.time, stage_fraction);
    const BoundaryShare b = boundary_share(fluid.methods.boundary, scene.colliders, scene.collider_count,
                                           xyz(a.sorted_position[i]), at.s, at.tau);
    s.density += b.density;
    a.boundary_gradient[i] = pack_boundary(b);
  }
  float rho = s.density;
  if (kNormalized) {
    // The carried factor, in the old order (nothing writes the factors in this kernel); the
    // kernel sum goes to the side array for the factor after the filter.
    float factor = a.density_factor[k];
    rho = carried_density(fluid, s.density, factor);
    a.normalized_density[i] = factor_to_side ? factor : s.density;
  }
  a.density[i] = rho;
  if (kCounts) a.neighbor_count[i] = s.neighbor_count;
  a.sorted_position[i].w = pressure_from_density(fluid.methods.eos, rho);
  const Float4 v = a.velocity[k];
  a.sorted_velocity[i] = make_float4_record(xyz(v), 1.0f / rho);
}

// A distributed rank's ghosts, which density_kernel skips: the velocity moved to the sorted order
// (their density records do not carry it) and placeholders that keep the record finite until the
// owners' records arrive (the pressure slot held the old index until here). Not written for a
// ghost: the walls' share (boundary_gradient; each particle's force and load read only its own, and
// ghosts are neither integrated nor loaded), the normalised density's factor (only its own filter,
// skipped too, reads it).
__global__ void ghost_density_moves_kernel(FluidConstants fluid, ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || !a.halo_ghost[i]) return;
  const uint32_t k = __float_as_uint(a.sorted_position[i].w);
  a.density[i] = fluid.rest_density;
  a.sorted_position[i].w = 0.0f;
  a.sorted_velocity[i] = make_float4_record(xyz(a.velocity[k]), 1.0f / fluid.rest_density);
  if (a.normalized_density) a.normalized_density[i] = fluid.rest_density;  // (the filter skips it too)
}

// Eq. 31 reads every carried rho_j: the factor is written in the new order
// (the density kernel is done reading the old), the filtered density into the side array,
// and both are published after every particle has been filtered.
__global__ void normalized_density_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                          const FrameState* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  // (A rank's ghost: its published density is its owner's, taken after the publication.)
  if (i >= n || is_halo_ghost(a, i)) return;
  const float filtered = gather_normalized_density(fluid, grid, a.sorted_position, a.sorted_velocity, i);
  const float share =
      density_factor_relaxation(state->clock.dt_float, speed_of_sound(fluid.methods.eos), fluid.kernel.h);
  const FilteredDensity d = filtered_density(fluid, filtered, a.normalized_density[i], share);
  a.density_factor[i] = d.factor;
  a.normalized_density[i] = d.density;
}

__global__ void publish_normalized_density_kernel(FluidConstants fluid, ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float rho = a.normalized_density[i];
  a.density[i] = rho;
  a.sorted_position[i].w = pressure_from_density(fluid.methods.eos, rho);
  a.sorted_velocity[i].w = 1.0f / rho;
}

// The delta-SPH rate over every published rho_j: the diffused density goes to the side array
// (free once the filtered densities are published) and the factor that carries it is written;
// publish_normalized_density_kernel then publishes them.
__global__ void density_diffusion_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                         const FrameState* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || is_halo_ghost(a, i)) return;  // (a rank's ghost: as the filter's)
  const float rate = gather_density_diffusion(fluid, fluid.methods.density_diffusion, grid, a.sorted_position,
                                              a.sorted_velocity, i);
  // The side array holds this particle's resolved factor (density_kernel's factor_to_side).
  const DiffusedDensity d = diffused_density(fluid, fluid.methods.density_diffusion, a.density[i],
                                             a.normalized_density[i], rate, state->clock.dt_float);
  a.density_factor[i] = d.factor;
  a.normalized_density[i] = d.density;
}

// Without diffusion in this pass: the resolved factors, from the side array, in the new order.
__global__ void carry_density_factor_kernel(ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  a.density_factor[i] = a.normalized_density[i];
}

__global__ void colour_normal_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || is_halo_ghost(a, i)) return;  // (a rank's ghost takes its owner's normal after)
  a.colour_normal[i] = gather_colour_normal(fluid, grid, a.sorted_position, a.sorted_velocity, i);
}

// One launch of the density kernel with its options as template arguments.
template <bool kCounts, bool kNormalized>
void launch_density(bool boundary, unsigned lanes, unsigned threads, const FluidConstants& fluid,
                    const GridView& grid, const ParticleArrays& a, uint32_t n, const DeviceScene& scene,
                    float stage_fraction, bool factor_to_side, FrameState* state, cudaStream_t stream) {
  const auto launch = [&](auto kernel) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for_lanes(n, lanes, t), t, 0, stream>>>(fluid, grid, a, n, scene, stage_fraction,
                                                            factor_to_side, state);
  };
  with_lanes(lanes, [&](auto g) {
    constexpr unsigned G = decltype(g)::value;
    if (boundary)
      launch(density_kernel<kCounts, kNormalized, true, G>);
    else
      launch(density_kernel<kCounts, kNormalized, false, G>);
  });
}

}  // namespace

void enqueue_density(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a, uint32_t n,
                     const SubstepOptions& options, const KernelTuning& tuning, const DeviceScene& scene,
                     float stage_fraction, bool first_of_substep, FrameState* state, cudaStream_t stream) {
  enqueue_density_summation(fluid, grid, a, n, options, tuning, scene, stage_fraction, state, stream);
  enqueue_density_republish(fluid, grid, a, n, options, tuning, first_of_substep, state, stream);
  if (options.surface_tension) enqueue_colour_normals(fluid, grid, a, n, tuning, stream);
}

void enqueue_density_summation(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                               const DeviceScene& scene, float stage_fraction, FrameState* state,
                               cudaStream_t stream) {
  const unsigned threads = tuning.density_block;
  const unsigned lanes = lanes_per_particle(tuning, n);
  const bool counts = options.viscosity == ViscosityMethod::Clavet;
  const bool boundary = options.boundary_density;
  if (counts && options.normalized_density)
    launch_density<true, true>(boundary, lanes, threads, fluid, grid, a, n, scene, stage_fraction,
                               options.density_diffusion, state, stream);
  else if (counts)
    launch_density<true, false>(boundary, lanes, threads, fluid, grid, a, n, scene, stage_fraction,
                                options.density_diffusion, state, stream);
  else if (options.normalized_density)
    launch_density<false, true>(boundary, lanes, threads, fluid, grid, a, n, scene, stage_fraction,
                                options.density_diffusion, state, stream);
  else
    launch_density<false, false>(boundary, lanes, threads, fluid, grid, a, n, scene, stage_fraction,
                                 options.density_diffusion, state, stream);
  check_launch("density_kernel");
  if (a.halo_ghost) {  // a distributed rank's world
    const unsigned t = fit_block(ghost_density_moves_kernel, threads);
    ghost_density_moves_kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, a, n);
    check_launch("ghost_density_moves_kernel");
  }
}

bool enqueue_density_republish(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                               bool first_of_substep, FrameState* state, cudaStream_t stream) {
  const unsigned threads = tuning.density_block;
  if (options.density_diffusion) {
    // The diffusion keeps the carried density instead of the filter (density_diffusion.h).
    if (first_of_substep) {  // once per substep, for its whole dt
      enqueue_density_diffusion(fluid, grid, a, n, tuning, state, stream);
    } else {
      const unsigned t = fit_block(carry_density_factor_kernel, threads);
      carry_density_factor_kernel<<<blocks_for(n, t), t, 0, stream>>>(a, n);
      check_launch("carry_density_factor_kernel");
    }
  } else if (options.normalized_density) {
    const unsigned t = fit_block(normalized_density_kernel, threads);
    normalized_density_kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, grid, a, n, state);
    check_launch("normalized_density_kernel");
    const unsigned tp = fit_block(publish_normalized_density_kernel, threads);
    publish_normalized_density_kernel<<<blocks_for(n, tp), tp, 0, stream>>>(fluid, a, n);
    check_launch("publish_normalized_density_kernel");
    return true;
  }
  return options.density_diffusion && first_of_substep;
}

void enqueue_density_diffusion(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const KernelTuning& tuning, FrameState* state,
                               cudaStream_t stream) {
  const unsigned t = fit_block(density_diffusion_kernel, tuning.density_block);
  density_diffusion_kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, grid, a, n, state);
  check_launch("density_diffusion_kernel");
  const unsigned tp = fit_block(publish_normalized_density_kernel, tuning.density_block);
  publish_normalized_density_kernel<<<blocks_for(n, tp), tp, 0, stream>>>(fluid, a, n);
  check_launch("publish_normalized_density_kernel");
}

void enqueue_colour_normals(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                            uint32_t n, const KernelTuning& tuning, cudaStream_t stream) {
  const unsigned t = fit_block(colour_normal_kernel, tuning.density_block);
  colour_normal_kernel<<<blocks_for(n, t), t, 0, stream>>>(fluid, grid, a, n);
  check_launch("colour_normal_kernel");
}

}  // namespace sph
