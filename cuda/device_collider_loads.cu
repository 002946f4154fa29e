// SPDX-License-Identifier: MIT
#include "../src/physics/boundary_density.h"
#include "../src/physics/integrate.h"
#include "block_reduce.cuh"
#include "device_collider_loads.h"
#include "kernel_launch.h"
#include "substep_kernels.h"

namespace sph {
namespace {

// Sums one LoadImpulse per thread over the block in a fixed tree (the same bits whatever the
// order blocks run in) and writes it to *out from thread 0. Call from every thread.
__device__ __forceinline__ void block_sum_to(const LoadImpulse& mine, float (*slots)[kLoadBlock],
                                             LoadImpulse* out) {
  const unsigned t = threadIdx.x;
  slots[0][t] = mine.linear.x, slots[1][t] = mine.linear.y, slots[2][t] = mine.linear.z;
  slots[3][t] = mine.angular.x, slots[4][t] = mine.angular.y, slots[5][t] = mine.angular.z;
  __syncthreads();
  for (unsigned stride = kLoadBlock / 2; stride > 0; stride >>= 1) {
    if (t < stride)
      for (int k = 0; k < 6; ++k) slots[k][t] += slots[k][t + stride];
    __syncthreads();
  }
  if (t == 0)
    *out =
        LoadImpulse{Vec3{slots[0][0], slots[1][0], slots[2][0]}, Vec3{slots[3][0], slots[4][0], slots[5][0]}};
  __syncthreads();  // the slots are reused by the next collider
}

template <bool kWalls, bool kContacts>
__global__ void __launch_bounds__(kLoadBlock)
    loads_kernel(FluidConstants fluid, ParticleArrays a, uint32_t n, DeviceScene scene, DeviceLoads loads,
                 float stage_fraction, float wall_weight, bool rk4, FrameState* state) {
  __shared__ float slots[6][kLoadBlock];
  mark_stage(state, kStageCollide);
  const uint32_t i = blockIdx.x * kLoadBlock + threadIdx.x;
  // A distributed rank's ghosts are another rank's particles: that rank adds their impulses.
  const bool live = i < n && !(a.halo_ghost && a.halo_ghost[i]);
  const SubstepTime time = state->clock.time;
  const StageTime at = stage_time(time, stage_fraction);
  const float mass = fluid.particle_mass;
  Vec3 wall_x{0.0f, 0.0f, 0.0f}, x{0.0f, 0.0f, 0.0f}, v{0.0f, 0.0f, 0.0f}, from{0.0f, 0.0f, 0.0f};
  float coefficient_dt = 0.0f;
  // DFSPH's contact clamp (collider_loads.h): its impulses at the substep's start.
  const bool clamped = live && a.dfsph_contact_impulse != nullptr;
  Float4 clamp{0.0f, 0.0f, 0.0f, 0.0f};
  Vec3 clamp_x{0.0f, 0.0f, 0.0f};
  uint32_t clamp_to = scene.collider_count;
  if (clamped) {
    clamp = a.dfsph_contact_impulse[i];
    clamp_x = xyz(a.sorted_position[i]);
    clamp_to = clamp_collider(clamp, scene.collider_count);
  }
  if (live && kWalls) {
    const Float4 p = a.sorted_position[i];
    const float inv_rho = a.sorted_velocity[i].w;
    wall_x = xyz(p);
    coefficient_dt = p.w * inv_rho * inv_rho * (wall_weight * time.dt);
  }
  if (live && kContacts) {
    x = xyz(a.position[i]);
    v = xyz(a.velocity[i]);
    from = rk4 ? a.rk4_start[0][i].position : xyz(a.sorted_position[i]);
  }
  for (uint32_t c = 0; c < scene.collider_count; ++c) {
    const ColliderView& view = scene.colliders[c];
    LoadImpulse mine = zero_load_impulse();
    if (live && kWalls) {
      const BoundaryShare share = collider_boundary_share(fluid.methods.boundary, view, wall_x, at.s, at.tau);
      add_load(mine, wall_reaction_impulse(share.gradient, mass, coefficient_dt), wall_x,
               load_point_at(view, at.s));
    }
    if (clamp_to == c) add_load(mine, clamp_impulse(mass, clamp), clamp_x, load_point_at(view, at.s));
    if (live && kContacts) {
      const Vec3 before = v;
      collide_particle(view, time, scene.kernel_radius, from, x, v);
      add_load(mine, contact_impulse(mass, before, v), x, load_point_at(view, time.s1));
    }
    block_sum_to(mine, slots, &loads.partials[static_cast<size_t>(blockIdx.x) * loads.colliders + c]);
  }
  if (kContacts) {
    // The force kernel left the collision response and the state's max speed to this pass.
    float v2 = 0.0f;
    if (live) {
      a.position[i] = make_float4_record(x, a.position[i].w);
      a.velocity[i] = make_float4_record(v, a.velocity[i].w);
      v2 = length_squared(v);
      if (!isfinite(v2)) v2 = 0.0f;
    }
    block_max_to(&state->v2max_bits, v2);
  }
}

// The blocks' sums in block order, in double, into the frame's sums: one thread per collider.
__global__ void loads_sum_kernel(DeviceLoads loads, uint32_t blocks) {
  const uint32_t c = blockIdx.x * blockDim.x + threadIdx.x;
  if (c >= loads.colliders) return;
  ColliderLoadSums& sum = loads.sums[c];
  double l[3] = {sum.linear[0], sum.linear[1], sum.linear[2]};
  double r[3] = {sum.angular[0], sum.angular[1], sum.angular[2]};
  for (uint32_t b = 0; b < blocks; ++b) {
    const LoadImpulse& p = loads.partials[static_cast<size_t>(b) * loads.colliders + c];
    l[0] += p.linear.x, l[1] += p.linear.y, l[2] += p.linear.z;
    r[0] += p.angular.x, r[1] += p.angular.y, r[2] += p.angular.z;
  }
  for (int k = 0; k < 3; ++k) sum.linear[k] = l[k], sum.angular[k] = r[k];
}

template <bool kWalls, bool kContacts>
void launch_loads(unsigned blocks, const FluidConstants& fluid, const ParticleArrays& a, uint32_t n,
                  const DeviceScene& scene, const DeviceLoads& loads, float stage_fraction, float wall_weight,
                  bool rk4, FrameState* state, cudaStream_t stream) {
  loads_kernel<kWalls, kContacts>
      <<<blocks, kLoadBlock, 0, stream>>>(fluid, a, n, scene, loads, stage_fraction, wall_weight, rk4, state);
}

}  // namespace

DeviceLoads DeviceColliderLoads::reserve(uint32_t colliders, uint32_t capacity) {
  const size_t partials = static_cast<size_t>(blocks_for(capacity, kLoadBlock)) * colliders;
  // A new generation before any buffer is freed, so that a failure below leaves it changed too.
  if (partials > partial_slots_ || colliders > sum_slots_) generation_ = next_buffer_generation();
  // allocate() frees the old buffer first: the slot counts drop to 0 until the new one is there,
  // so a failed allocation cannot leave a count that a later, smaller frame trusts.
  if (partials > partial_slots_) {
    partial_slots_ = 0;
    partials_.allocate(partials, "the loads' block sums");
    partial_slots_ = partials;
  }
  if (colliders > sum_slots_) {
    sum_slots_ = 0;
    sums_.allocate(colliders, "the loads' frame sums");
    output_.allocate(colliders, "the loads' host copy");
    sum_slots_ = colliders;
  }
  DeviceLoads d;
  d.partials = partials_.get();
  d.sums = sums_.get();
  d.output = output_.get();
  d.colliders = colliders;
  d.generation = generation_;
  return d;
}

void enqueue_loads_begin(const DeviceLoads& loads, cudaStream_t stream) {
  cuda_check(cudaMemsetAsync(loads.sums, 0, sizeof(ColliderLoadSums) * loads.colliders, stream),
             "zeroing of the loads");
}

void enqueue_loads_end(const DeviceLoads& loads, cudaStream_t stream) {
  cuda_check(cudaMemcpyAsync(loads.output, loads.sums, sizeof(ColliderLoadSums) * loads.colliders,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the loads");
}

void enqueue_loads(const FluidConstants& fluid, const ParticleArrays& a, uint32_t n, const DeviceScene& scene,
                   const DeviceLoads& loads, bool boundary_density, float stage_fraction, float wall_weight,
                   bool contacts, bool rk4, FrameState* state, cudaStream_t stream) {
  const unsigned blocks = blocks_for(n, kLoadBlock);
  if (boundary_density && contacts)
    launch_loads<true, true>(blocks, fluid, a, n, scene, loads, stage_fraction, wall_weight, rk4, state,
                             stream);
  else if (boundary_density)
    launch_loads<true, false>(blocks, fluid, a, n, scene, loads, stage_fraction, wall_weight, rk4, state,
                              stream);
  else
    launch_loads<false, true>(blocks, fluid, a, n, scene, loads, stage_fraction, wall_weight, rk4, state,
                              stream);
  check_launch("loads_kernel");
  loads_sum_kernel<<<blocks_for(loads.colliders, 64), 64, 0, stream>>>(loads, blocks);
  check_launch("loads_sum_kernel");
}

}  // namespace sph
