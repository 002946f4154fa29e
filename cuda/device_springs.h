// SPDX-License-Identifier: MIT
// Springs on the device (SPH_FEATURE_SPRINGS; the physics is src/physics/springs.h, shared
// with the CPU backend). Per sort: the lists follow the permutation with their partners
// rewritten (enqueue_spring_reorder); per force evaluation, after the density pass: the
// particles waiting for springs make them (two passes, skipped on the device when none
// waits), then each particle's spring acceleration goes to a side array that the force pass
// adds, and the lists go back into the state in the new order (enqueue_spring_pass).
// Sinks: enqueue_spring_compact moves the lists with the survivors.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <vector>

#include "../src/physics/neighbor_walk.h"
#include "../src/physics/springs.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

// The CUDA backend's own working arrays for springs, beyond the method's (particle_arrays.h):
// the lists' sorted working copy (also the compaction's target) and the inverse permutation for
// the partner rewrite. Added to a springs world's registrations (cuda_backend.cu).
constexpr const char* kArraySortedSprings = "sorted_springs";
constexpr const char* kArraySpringInverse = "spring_inverse";
std::vector<ParticleArraySpec> spring_device_arrays();

// sorted_springs[i] = springs[order[i]] with partners mapped to their new indices.
void enqueue_spring_reorder(const ParticleArrays& a, const uint32_t* order, uint32_t n, cudaStream_t stream);

// Linking (when a particle waits), then spring_acceleration[i] from the sorted state; with
// update_rest (a substep's first force evaluation) the rest lengths flow. Writes the lists
// back to a.springs in the sorted order, which the force pass makes the state order.
void enqueue_spring_pass(const SpringConstants& c, const GridView& grid, const ParticleArrays& a, uint32_t n,
                         bool update_rest, FrameState* state, cudaStream_t stream);

// A sink's stable compaction: survivor i goes to scan[i]; springs to removed particles drop.
void enqueue_spring_compact(const ParticleArrays& a, uint32_t n, uint32_t kept, const uint32_t* keep,
                            const uint32_t* scan, cudaStream_t stream);

// After an append of particles with ids from first_id: link_from = min(link_from, first_id).
void enqueue_springs_appended(const ParticleArrays& a, uint32_t first_id, cudaStream_t stream);

}  // namespace sph
