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

// A distributed rank's ghosts (a.halo_ghost, sorted order; null in an undivided world) neither
// link nor move: their lists name partners by id (their owners compute their springs), the
// reorder moves them unchanged, pass 1 gives them no candidates of their own (a rank's step takes
// their owners') and the force pass none (cuda_halo_springs.cu, as src/cpu/cpu_springs.cpp).

// sorted_springs[i] = springs[order[i]] with partners mapped to their new indices (a ghost's
// list unchanged).
void enqueue_spring_reorder(const ParticleArrays& a, const uint32_t* order, uint32_t n, cudaStream_t stream);

// A distributed rank's step between linking's two passes: the ghosts take their owners'
// candidates (SubstepHooks, substep_pipeline.h).
struct SpringRankStep {
  virtual ~SpringRankStep() = default;
  virtual void between_link_passes(cudaStream_t stream) = 0;
};

// Linking (when a particle waits), then spring_acceleration[i] from the sorted state; with
// update_rest (a substep's first force evaluation) the rest lengths flow. Writes the lists
// back to a.springs in the sorted order, which the force pass makes the state order. rank: a
// distributed rank's step between the link passes (null otherwise).
void enqueue_spring_pass(const SpringConstants& c, const GridView& grid, const ParticleArrays& a, uint32_t n,
                         bool update_rest, FrameState* state, cudaStream_t stream,
                         SpringRankStep* rank = nullptr);

// A sink's stable compaction: survivor i goes to scan[i]; springs to removed particles drop.
// partner_ids (a distributed rank between substeps: the lists name partners by id): the lists
// move unchanged, and a spring to a removed particle drops at the next substep (no particle
// holds its id then).
void enqueue_spring_compact(const ParticleArrays& a, uint32_t n, uint32_t kept, const uint32_t* keep,
                            const uint32_t* scan, bool partner_ids, cudaStream_t stream);

// After an append of particles with ids from first_id: link_from = min(link_from, first_id).
void enqueue_springs_appended(const ParticleArrays& a, uint32_t first_id, cudaStream_t stream);

}  // namespace sph
