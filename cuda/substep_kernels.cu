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
#include "lane_launch.cuh"
#include "substep_kernels.h"

namespace sph {
namespace {

using lanes::blocks_for_lanes;
using lanes::grid_thread;
using lanes::with_lanes;

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
  // A distributed rank's ghost is its owner's to move (no gather: the whole lane group is one
  // particle); it leaves no trace in the maxima.
  const bool own = i < n && !is_halo_ghost(a, i);
  if (own) {
    f.dt = state->clock.dt_float;  // impulse-based terms need the substep's length
    acc = gather_acceleration_masked<Terms, true, G>(f, grid, a.sorted_position, a.sorted_velocity,
                                                     a.neighbor_count, a.colour_normal, i, group);
  }
  if (own && group.lane == 0) {
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
    if (!state_finite(next.position, p.w, v2, v.w)) {
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
  // A distributed rank's ghost is its owner's to move (no gather); it leaves no trace in the maxima.
  const bool own = i < n && !is_halo_ghost(a, i);
  if (own) {
    f.dt = state->clock.dt_float;
    acc = gather_acceleration_masked<Terms, true, G>(f, grid, a.sorted_position, a.sorted_velocity,
                                                     a.neighbor_count, a.colour_normal, i, group);
  }
  if (own && group.lane == 0) {
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
    if (!state_finite(next.position, p.w, v2, v.w)) {
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

// One launch site per combination of force terms (with_force_terms, methods.h): a world that
// does not use a method runs code without it. A frame without colliders and force fields runs
// kernels without the scene code.
void enqueue_forces_euler(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                          uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                          const DeviceScene& scene, bool collide_here, FrameState* state,
                          cudaStream_t stream) {
  const unsigned threads = tuning.force_block, lanes = lanes_per_particle(tuning, n);
  const auto launch = [&](auto kernel, bool collide) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for_lanes(n, lanes, t), t, 0, stream>>>(fluid, grid, a, n, scene, collide, state);
  };
  with_force_terms(options.methods, [&](auto terms) {
    using Terms = decltype(terms);
    with_lanes(lanes, [&](auto g) {
      constexpr unsigned G = decltype(g)::value;
      if (scene.active())
        launch(forces_euler_kernel<Terms, true, G>, collide_here);
      else
        launch(forces_euler_kernel<Terms, false, G>, true);
    });
  });
  check_launch("forces_euler_kernel");
}

void enqueue_forces_rk4(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                        uint32_t n, int stage, const SubstepOptions& options, const KernelTuning& tuning,
                        const DeviceScene& scene, bool collide_here, FrameState* state, cudaStream_t stream) {
  const unsigned threads = tuning.force_block, lanes = lanes_per_particle(tuning, n);
  const auto launch = [&](auto kernel, bool collide) {
    const unsigned t = fit_block(kernel, threads);
    kernel<<<blocks_for_lanes(n, lanes, t), t, 0, stream>>>(fluid, grid, a, n, stage, scene, collide, state);
  };
  with_force_terms(options.methods, [&](auto terms) {
    using Terms = decltype(terms);
    with_lanes(lanes, [&](auto g) {
      constexpr unsigned G = decltype(g)::value;
      if (scene.active())
        launch(forces_rk4_kernel<Terms, true, G>, collide_here);
      else
        launch(forces_rk4_kernel<Terms, false, G>, true);
    });
  });
  check_launch("forces_rk4_kernel");
}

}  // namespace sph
