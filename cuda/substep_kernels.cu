// SPDX-License-Identifier: MIT
#include <type_traits>

#include "../src/physics/boundary_density.h"
#include "../src/physics/density.h"
#include "../src/physics/density_diffusion.h"
#include "../src/physics/density_normalization.h"
#include "../src/physics/forces.h"
#include "../src/physics/integrate.h"
#include "../src/physics/surface_tension.h"
#include "block_reduce.cuh"
#include "force_gather.cuh"
#include "kernel_launch.h"
#include "substep_kernels.h"

namespace sph {
namespace {

template <Rk4Carry Carry>
__global__ void reorder_kernel(ParticleArrays a, const uint32_t* __restrict__ order, uint32_t n, int from,
                               CrowdGuard guard, FrameState* state) {
  mark_stage(state, kStageHashSort);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const unsigned long long crowded = state->crowded_key;
  if (crowded != 0) {
    // Every range empty: the failing substep's walks cost nothing, whatever the pile.
    for (uint64_t e = i; e < guard.entries; e += static_cast<uint64_t>(gridDim.x) * blockDim.x)
      guard.cell_start[e] = 0;
    const uint32_t slot = static_cast<uint32_t>(crowded & 0xffffffffu);
    if (i < n && guard.sorted_keys[i] == slot && (i == 0 || guard.sorted_keys[i - 1] != slot)) {
      const Float4 p = a.position[order[i]];
      state->crowded_where[0] = p.x, state->crowded_where[1] = p.y, state->crowded_where[2] = p.z;
    }
  }
  if (i >= n) return;
  const uint32_t k = order[i];
  const Float4 p = a.position[k];
  a.sorted_position[i] = Float4{p.x, p.y, p.z, __uint_as_float(k)};
  a.sorted_id[i] = a.id[k];
  if (a.user_attribute) a.sorted_user_attribute[i] = a.user_attribute[k];
  if (Carry == Rk4Carry::BuildStart) {
    a.rk4_start[1][i] = ParticleState{xyz(p), xyz(a.velocity[k])};
  } else if (Carry == Rk4Carry::Gather) {
    // Constant indices only: a run-time index into the by-value struct would put it in local memory.
    if (from == 0) {
      a.rk4_start[1][i] = a.rk4_start[0][k];
      a.rk4_sum[1][i] = a.rk4_sum[0][k];
    } else {
      a.rk4_start[0][i] = a.rk4_start[1][k];
      a.rk4_sum[0][i] = a.rk4_sum[1][k];
    }
  }
}

// The user attribute back into the state arrays after its gather (a kernel rather than a memcpy:
// the substep is the body of the frame graph's conditional WHILE node, which takes kernels).
__global__ void user_attribute_copy_kernel(const uint32_t* __restrict__ sorted, uint32_t n, uint32_t* state) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) state[i] = sorted[i];
}

// The thread's index in the grid (64 bits: n particles of G lanes can pass 2^32 threads).
__device__ __forceinline__ unsigned long long grid_thread() {
  return static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
}

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

// Eq. 31 reads every carried rho_j: the factor is written in the new order
// (the density kernel is done reading the old), the filtered density into the side array,
// and both are published after every particle has been filtered.
__global__ void normalized_density_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float filtered = gather_normalized_density(fluid, grid, a.sorted_position, a.sorted_velocity, i);
  a.density_factor[i] = filtered / a.normalized_density[i];
  a.normalized_density[i] = filtered;
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
  if (i >= n) return;
  const float rate = gather_density_diffusion(fluid, fluid.methods.density_diffusion, grid, a.sorted_position,
                                              a.sorted_velocity, i);
  // The side array holds this particle's resolved factor (density_kernel's factor_to_side).
  const DiffusedDensity d =
      diffused_density(a.density[i], a.normalized_density[i], rate, state->clock.dt_float);
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
  if (i >= n) return;
  a.colour_normal[i] = gather_colour_normal(fluid, grid, a.sorted_position, a.sorted_velocity, i);
}

// G: the lane group (LaneGroup); every lane gathers, lane 0 integrates and writes the particle,
// and every thread of the block joins the block maxima.
template <class Terms, bool kScene, unsigned G>
__global__ void forces_euler_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                    DeviceScene scene, bool collide_here, FrameState* state) {
  mark_stage(state, kStageForces);
  const unsigned long long t = grid_thread();
  const uint32_t i = t / G < n ? static_cast<uint32_t>(t / G) : n;  // whole groups past the end
  const LaneGroup<G> group = LaneGroup<G>::of_thread(t);
  float v2 = 0.0f, a2 = 0.0f;
  Vec3 acc{0.0f, 0.0f, 0.0f};
  FluidConstants f = fluid;
  if (i < n) {
    f.dt = state->clock.dt_float;  // impulse-based terms need the substep's length
    acc = gather_acceleration_masked<Terms, true, G>(f, grid, a.sorted_position, a.sorted_velocity,
                                                     a.neighbor_count, a.colour_normal, i, group);
  }
  if (i < n && group.lane == 0) {
    const Float4 p = a.sorted_position[i];
    const Float4 v = a.sorted_velocity[i];
    if (kScene) acc = add_force_fields(scene, acc, xyz(p));
    if (a.spring_acceleration) acc += xyz(a.spring_acceleration[i]);  // springs (device_springs.h)
    if (a.boundary_gradient) acc += boundary_pressure_acceleration(a.boundary_gradient[i], p.w, v.w);
    a2 = length_squared(acc);
    ParticleState next = symplectic_euler(ParticleState{xyz(p), xyz(v)}, acc, f.dt);
    const ParticleState integrated = next;
    if (kScene && collide_here) collide_all(scene, state->clock.time, xyz(p), next);
    const uint32_t id = a.sorted_id[i];
    a.position[i] = make_float4_record(next.position, p.w);
    a.velocity[i] = make_float4_record(next.velocity, v.w);
    a.id[i] = id;
    v2 = length_squared(next.velocity);
    if (!finite3(next.position) || !isfinite(v2)) {
      flag_non_finite(state, 0, i, id, classify_non_finite(a.density[i], p, v, acc, integrated));
      v2 = 0.0f;
    }
    if (!collide_here) v2 = 0.0f;  // the loads pass collides and takes the speed (device_collider_loads.h)
  }
  block_max_to(&state->v2max_bits, v2);
  __syncthreads();  // block_max_to's shared slots are reused
  block_max_to(&state->a2max_bits, a2);
}

template <class Terms, bool kScene, unsigned G>
__global__ void forces_rk4_kernel(FluidConstants fluid, GridView grid, ParticleArrays a, uint32_t n,
                                  int stage, DeviceScene scene, bool collide_here, FrameState* state) {
  mark_stage(state, kStageForces);
  const unsigned long long t = grid_thread();
  const uint32_t i = t / G < n ? static_cast<uint32_t>(t / G) : n;  // whole groups past the end
  const LaneGroup<G> group = LaneGroup<G>::of_thread(t);
  float v2 = 0.0f, a2 = 0.0f;
  Vec3 acc{0.0f, 0.0f, 0.0f};
  FluidConstants f = fluid;
  if (i < n) {
    f.dt = state->clock.dt_float;
    acc = gather_acceleration_masked<Terms, true, G>(f, grid, a.sorted_position, a.sorted_velocity,
                                                     a.neighbor_count, a.colour_normal, i, group);
  }
  if (i < n && group.lane == 0) {
    // This stage's side, (stage + 1) % 2, picked without a run-time index into the struct.
    ParticleState* start = (stage & 1) ? a.rk4_start[0] : a.rk4_start[1];
    Rk4Accumulator* sums = (stage & 1) ? a.rk4_sum[0] : a.rk4_sum[1];
    const Float4 p = a.sorted_position[i];
    const Float4 v = a.sorted_velocity[i];
    if (kScene) acc = add_force_fields(scene, acc, xyz(p));
    if (a.spring_acceleration) acc += xyz(a.spring_acceleration[i]);  // springs (device_springs.h)
    if (a.boundary_gradient) acc += boundary_pressure_acceleration(a.boundary_gradient[i], p.w, v.w);
    a2 = length_squared(acc);
    Rk4Accumulator sum;
    if (stage > 0) sum = sums[i];  // stage 0 starts the sums
    const ParticleState from = start[i];
    ParticleState next = rk4_advance(stage, from, ParticleState{xyz(p), xyz(v)}, acc, f.dt, sum);
    sums[i] = sum;
    const ParticleState integrated = next;
    if (kScene && collide_here && stage == kRk4Stages - 1)
      collide_all(scene, state->clock.time, from.position, next);
    const uint32_t id = a.sorted_id[i];
    a.position[i] = make_float4_record(next.position, p.w);
    a.velocity[i] = make_float4_record(next.velocity, v.w);
    a.id[i] = id;
    v2 = length_squared(next.velocity);
    if (!finite3(next.position) || !isfinite(v2)) {
      flag_non_finite(state, stage, i, id, classify_non_finite(a.density[i], p, v, acc, integrated));
      v2 = 0.0f;
    }
    if (stage != kRk4Stages - 1) v2 = 0.0f;  // the speed that counts is the final state's
    if (!collide_here) v2 = 0.0f;            // the loads pass collides and takes the speed
  }
  if (stage == kRk4Stages - 1) {
    block_max_to(&state->v2max_bits, v2);
    __syncthreads();
  }
  block_max_to(&state->a2max_bits, a2);  // over all four stages, as the CPU backend
}

// One launch site per combination of force terms (with_force_terms, methods.h): a world that
// does not use a method runs code without it. A frame without colliders and force fields runs
// kernels without the scene code.

// Calls launch(std::integral_constant<unsigned, G>) for the lane group G = lanes (1, 2, 4, 8).
template <class Launch>
void with_lanes(unsigned lanes, Launch&& launch) {
  switch (lanes) {
    case 2:
      launch(std::integral_constant<unsigned, 2>{});
      break;
    case 4:
      launch(std::integral_constant<unsigned, 4>{});
      break;
    case 8:
      launch(std::integral_constant<unsigned, 8>{});
      break;
    default:
      launch(std::integral_constant<unsigned, 1>{});
      break;
  }
}

// Blocks for n particles of `lanes` threads each.
unsigned blocks_for_lanes(uint32_t n, unsigned lanes, unsigned threads) {
  const uint64_t items = static_cast<uint64_t>(n) * lanes;
  return items == 0 ? 1u : static_cast<unsigned>((items + threads - 1) / threads);
}

// One launch of the density kernel with its options as template arguments.
template <bool kCounts, bool kNormalized>
void launch_density(bool boundary, unsigned lanes, unsigned threads, const FluidConstants& fluid,
                    const GridView& grid, const ParticleArrays& a, uint32_t n, const DeviceScene& scene,
                    float stage_fraction, bool factor_to_side, FrameState* state, cudaStream_t stream) {
  const unsigned blocks = blocks_for_lanes(n, lanes, threads);
  with_lanes(lanes, [&](auto g) {
    constexpr unsigned G = decltype(g)::value;
    if (boundary)
      density_kernel<kCounts, kNormalized, true, G>
          <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, scene, stage_fraction, factor_to_side, state);
    else
      density_kernel<kCounts, kNormalized, false, G>
          <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, scene, stage_fraction, factor_to_side, state);
  });
}

}  // namespace

unsigned lanes_per_particle(const KernelTuning& tuning, uint32_t n) {
  if (tuning.particle_lanes != 0) return tuning.particle_lanes;
  // The gathers are latency-bound: they need more threads than the device holds at once to
  // hide it. Measured on an H200 (270,336 thread slots; docs/performance.md, session 9): at
  // 100k particles 4 lanes cut the substep by 17 % (2 by 7 %, 8 by 13 %); at 1M one lane is
  // fastest (2 lanes +1 %, 4 +8 %). So: the fewest lanes, up to 4, that fill the slots.
  unsigned lanes = 1u;
  while (lanes < 4u && static_cast<uint64_t>(n) * lanes < tuning.thread_slots) lanes *= 2u;
  return lanes;
}

void enqueue_reorder(const ParticleArrays& a, const uint32_t* order, uint32_t n, Rk4Carry carry, int from,
                     const CrowdGuard& guard, FrameState* state, cudaStream_t stream) {
  const unsigned blocks = blocks_for(n, kDefaultBlockSize);
  switch (carry) {
    case Rk4Carry::None:
      reorder_kernel<Rk4Carry::None>
          <<<blocks, kDefaultBlockSize, 0, stream>>>(a, order, n, from, guard, state);
      break;
    case Rk4Carry::BuildStart:
      reorder_kernel<Rk4Carry::BuildStart>
          <<<blocks, kDefaultBlockSize, 0, stream>>>(a, order, n, from, guard, state);
      break;
    case Rk4Carry::Gather:
      reorder_kernel<Rk4Carry::Gather>
          <<<blocks, kDefaultBlockSize, 0, stream>>>(a, order, n, from, guard, state);
      break;
  }
  check_launch("reorder_kernel");
  // The user attribute is no kernel's input: it takes the new order at once (every later pass
  // writes the state in the sorted order, so the two stay matched).
  if (a.user_attribute) {
    user_attribute_copy_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(a.sorted_user_attribute, n,
                                                                         a.user_attribute);
    check_launch("user_attribute_copy_kernel");
  }
}

void enqueue_density(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a, uint32_t n,
                     const SubstepOptions& options, const KernelTuning& tuning, const DeviceScene& scene,
                     float stage_fraction, bool first_of_substep, FrameState* state, cudaStream_t stream) {
  const unsigned threads = tuning.density_block, blocks = blocks_for(n, threads);
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
  if (options.density_diffusion) {
    // The diffusion keeps the carried density instead of the filter (density_diffusion.h).
    if (first_of_substep) {  // once per substep, for its whole dt
      enqueue_density_diffusion(fluid, grid, a, n, tuning, state, stream);
    } else {
      carry_density_factor_kernel<<<blocks, threads, 0, stream>>>(a, n);
      check_launch("carry_density_factor_kernel");
    }
  } else if (options.normalized_density) {
    normalized_density_kernel<<<blocks, threads, 0, stream>>>(fluid, grid, a, n);
    check_launch("normalized_density_kernel");
    publish_normalized_density_kernel<<<blocks, threads, 0, stream>>>(fluid, a, n);
    check_launch("publish_normalized_density_kernel");
  }
  if (options.surface_tension) enqueue_colour_normals(fluid, grid, a, n, tuning, stream);
}

void enqueue_density_diffusion(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const KernelTuning& tuning, FrameState* state,
                               cudaStream_t stream) {
  const unsigned threads = tuning.density_block, blocks = blocks_for(n, threads);
  density_diffusion_kernel<<<blocks, threads, 0, stream>>>(fluid, grid, a, n, state);
  check_launch("density_diffusion_kernel");
  publish_normalized_density_kernel<<<blocks, threads, 0, stream>>>(fluid, a, n);
  check_launch("publish_normalized_density_kernel");
}

void enqueue_colour_normals(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                            uint32_t n, const KernelTuning& tuning, cudaStream_t stream) {
  const unsigned threads = tuning.density_block, blocks = blocks_for(n, threads);
  colour_normal_kernel<<<blocks, threads, 0, stream>>>(fluid, grid, a, n);
  check_launch("colour_normal_kernel");
}

void enqueue_forces_euler(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                          uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                          const DeviceScene& scene, bool collide_here, FrameState* state,
                          cudaStream_t stream) {
  const unsigned threads = tuning.force_block, lanes = lanes_per_particle(tuning, n);
  const unsigned blocks = blocks_for_lanes(n, lanes, threads);
  with_force_terms(options.methods, [&](auto terms) {
    using Terms = decltype(terms);
    with_lanes(lanes, [&](auto g) {
      constexpr unsigned G = decltype(g)::value;
      if (scene.active())
        forces_euler_kernel<Terms, true, G>
            <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, scene, collide_here, state);
      else
        forces_euler_kernel<Terms, false, G>
            <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, scene, true, state);
    });
  });
  check_launch("forces_euler_kernel");
}

void enqueue_forces_rk4(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                        uint32_t n, int stage, const SubstepOptions& options, const KernelTuning& tuning,
                        const DeviceScene& scene, bool collide_here, FrameState* state, cudaStream_t stream) {
  const unsigned threads = tuning.force_block, lanes = lanes_per_particle(tuning, n);
  const unsigned blocks = blocks_for_lanes(n, lanes, threads);
  with_force_terms(options.methods, [&](auto terms) {
    using Terms = decltype(terms);
    with_lanes(lanes, [&](auto g) {
      constexpr unsigned G = decltype(g)::value;
      if (scene.active())
        forces_rk4_kernel<Terms, true, G>
            <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, stage, scene, collide_here, state);
      else
        forces_rk4_kernel<Terms, false, G>
            <<<blocks, threads, 0, stream>>>(fluid, grid, a, n, stage, scene, true, state);
    });
  });
  check_launch("forces_rk4_kernel");
}

}  // namespace sph
