// SPDX-License-Identifier: MIT
// Loads on colliders (SPH_FEATURE_COLLIDER_LOADS) on the device: the buffers of a frame's sums and
// the passes that fill them (the twin of src/cpu/cpu_collider_loads.cpp; the physics is
// src/physics/collider_loads.h). Per force evaluation, one kernel of kLoadBlock threads a block
// adds each particle's wall pressure reactions and, after the last stage, applies the collision
// response (which the force kernel then leaves to it) with its contact impulses; each block sums
// per collider in a fixed tree into its slot; a second kernel adds the blocks in order, in double,
// to the frame's sums. The sums are zeroed at the frame's begin and copied to pinned host memory
// at its end, inside the graph: no host round trip per substep, and the same bits every run.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/frame_report.h"
#include "../src/physics/collider_loads.h"
#include "device_array.h"
#include "frame_state.cuh"

namespace sph {

struct DeviceScene;
struct FluidConstants;
struct ParticleArrays;

// What the passes see (all null when the world's loads are off or the frame has no collider).
struct DeviceLoads {
  LoadImpulse* partials = nullptr;     // device, per block of kLoadBlock particles and collider
  ColliderLoadSums* sums = nullptr;    // device, per collider: the frame's impulses
  ColliderLoadSums* output = nullptr;  // pinned host, receives sums at the frame's end
  uint32_t colliders = 0;
  uint64_t generation = 0;  // host only: changes with every reallocation (next_buffer_generation)

  bool on() const { return sums != nullptr; }
};

// The buffers, grown (never shrunk) to the scene's collider count and the world's capacity.
class DeviceColliderLoads {
 public:
  DeviceLoads reserve(uint32_t colliders, uint32_t capacity);
  uint64_t bytes() const { return partials_.bytes() + sums_.bytes(); }

 private:
  DeviceArray<LoadImpulse> partials_;
  DeviceArray<ColliderLoadSums> sums_;
  PinnedArray<ColliderLoadSums> output_;
  size_t partial_slots_ = 0, sum_slots_ = 0;
  uint64_t generation_ = next_buffer_generation();
};

// The frame's sums to zero (frame begin) / to the pinned output (frame end).
void enqueue_loads_begin(const DeviceLoads& loads, cudaStream_t stream);
void enqueue_loads_end(const DeviceLoads& loads, cudaStream_t stream);

// One force evaluation's loads over n particles: the walls' pressure reactions (boundary density
// on) over wall_weight times the substep's dt at stage fraction `stage_fraction`, and, with
// contacts, the collision response of the integrated state (a.position / a.velocity) from its
// start (Euler and DFSPH: the sorted copy's position; RK4: rk4_start[0]), its speed into the
// frame's max. On a DFSPH world (a.dfsph_contact_impulse set) also the contact clamp's impulses,
// at the substep's start (collider_loads.h); its p is the one both solves applied, which
// enqueue_dfsph_step wrote into the sorted records.
void enqueue_loads(const FluidConstants& fluid, const ParticleArrays& a, uint32_t n, const DeviceScene& scene,
                   const DeviceLoads& loads, bool boundary_density, float stage_fraction, float wall_weight,
                   bool contacts, bool rk4, FrameState* state, cudaStream_t stream);

}  // namespace sph
