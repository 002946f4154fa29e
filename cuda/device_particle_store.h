// SPDX-License-Identifier: MIT
// The device-resident particle state of one world, as a structure of arrays, allocated for the
// world's capacity (a world that grows makes a larger store and copies the state over). The core state has
// fixed arrays:
//   position/velocity/id/density  the state in the current order (what callers read)
//   sorted_*                      the working copy in the order of the last sort; the density
//                                 pass reads it and the force pass writes the state from it.
//                                 sorted_velocity doubles as the radix sort's key/value
//                                 buffers, which are dead before the density pass fills it.
//   snapshot_*                    the state at the start of a frame, for the rollback
// The methods' arrays are allocated from their registrations (src/core/particle_arrays.h:
// name, element size, role), only for a world that uses the method, with their role's
// bookkeeping: a Carried array gets a snapshot copy, which enqueue_snapshot/enqueue_restore
// fill and read with the core state, and travels in appends and checkpoints by name; a Sorted
// array gets two sides, between which the reorder gathers (RK4's start state and slope sums); a
// Scratch array is one buffer. The kernels see raw pointers (ParticleArrays), looked up by name
// once, when the store is made. Reordering a method's carried array at a sort is its own
// kernels' work (the density pass gathers the density factor through the old index; the spring
// pass remaps the spring lists), a sink's compaction moves it (device_sinks.cu).
// Float4 records carry a second quantity in w: position.w = pressure, velocity.w = 1/density.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "../src/core/particle_arrays.h"
#include "../src/physics/dfsph.h"
#include "../src/physics/float4_types.h"
#include "../src/physics/integrate.h"
#include "../src/physics/springs.h"
#include "device_array.h"

namespace sph {

// Raw pointers, passed by value into kernels; the methods' are looked up by name once
// (particle_arrays.h names them), null where the world does not use the method.
struct ParticleArrays {
  Float4* position;
  Float4* velocity;
  uint32_t* id;
  float* density;
  Float4* sorted_position;
  Float4* sorted_velocity;
  uint32_t* sorted_id;
  ParticleState* rk4_start[2];  // null unless RK4
  Rk4Accumulator* rk4_sum[2];
  uint32_t* neighbor_count;   // null unless Clavet viscosity: the density pass's counts
  float* normalized_density;  // null unless normalised density: the kernel sum, then eq. 31
  float* density_factor;      // null unless normalised density: carried factor (state)
  Float4* colour_normal;      // null unless surface tension: (n, |n|) of the colour field
  // Null unless SPH_FEATURE_SPRINGS.
  SpringList* springs;          // the lists in state order (partners: state indices)
  SpringList* sorted_springs;   // the lists in the order of the last sort (working copy)
  uint32_t* spring_inverse;     // new index of each old index, for the partner rewrite
  uint32_t* spring_candidates;  // kSpringSlots per particle: linking pass 1
  Float4* spring_acceleration;  // the spring pass's acceleration, which the force pass adds
  uint32_t* link_from;          // one word: the lowest id waiting for springs, or kNoPendingLinks
  // Null unless the DFSPH solver (physics/dfsph.h). The carried pressures are in the state
  // order until the solves of a substep rewrite them in the sorted order (dfsph_solver.cu).
  float* dfsph_pressure;          // the density solve's p / rho^2 (carried)
  float* dfsph_divergence;        // the divergence solve's p / rho^2 times dt (carried)
  float* dfsph_factor;            // alpha / rho of the density pass
  float* dfsph_step;              // the iteration's p / rho^2, which neighbours read
  float* dfsph_warm_pressure;     // the density solve's warm start in the sorted order
  Float4* dfsph_contact;          // the particle's contact with the colliders (n, smallest normal speed)
  Float4* dfsph_contact_impulse;  // null unless SPH_FEATURE_COLLIDER_LOADS: the clamp's (collider_loads.h)
  float* dfsph_residual;          // the conjugate gradients' preconditioned residual z
  // The density pass's candidate masks for the solves' passes (kNeighborMaskWords words a
  // particle, physics/neighbor_walk.h); null unless DFSPH, or with sph_context_def.cuda_dfsph_masks off.
  uint32_t* dfsph_neighbor_mask;
  // The solves' neighbour lists (kNeighborListRows uint32 a particle, slot-major with stride
  // dfsph_list_stride, the capacity; physics/neighbor_walk.h), written by the density pass in the
  // walk that records the masks; null unless sph_context_def.cuda_dfsph_masks =
  // SPH_CUDA_DFSPH_NEIGHBOR_LISTS.
  uint32_t* dfsph_neighbor_list;
  uint32_t dfsph_list_stride;
  // Null where the conjugate gradients cannot run (particle_arrays.cpp): their density solve's
  // rho* - rho0, its change along the search direction, that direction's velocity change, flags.
  float* dfsph_cg_value;
  float* dfsph_cg_change;
  Float4* dfsph_cg_velocity_step;
  uint8_t* dfsph_cg_state;
  // Null unless SPH_FEATURE_BOUNDARY_DENSITY: (grad rho_b, v_b . grad rho_b) of the density pass.
  Float4* boundary_gradient;
  // Null unless SPH_FEATURE_USER_ATTRIBUTE: the caller's value in the state order, and the
  // reorder's gather target, copied back over it right after (substep_kernels.cu).
  uint32_t* user_attribute;
  uint32_t* sorted_user_attribute;
  // Null unless a distributed world's rank (cuda_halo.cu): in the sorted order of the substep,
  // non-zero for a ghost (a neighbour's particle, read by the neighbour passes, never moved).
  uint32_t* halo_ghost;
};

// Whether sorted particle i is a distributed rank's ghost (never in an undivided world). A ghost's
// sums are its owner's, taken after each pass that publishes them, so the neighbour passes skip
// its gathers (what a ghost's own sum would give, over a neighbourhood this rank does not hold
// whole, was only ever overwritten).
__host__ __device__ inline bool is_halo_ghost(const ParticleArrays& a, uint32_t i) {
  return a.halo_ghost && a.halo_ghost[i];
}

// This backend's working array for the user attribute's reorder (SPH_FEATURE_USER_ATTRIBUTE).
constexpr const char* kArraySortedUserAttribute = "sorted_user_attribute";
// A distributed rank's ghost mask (ParticleArrays::halo_ghost; Scratch).
constexpr const char* kArrayHaloGhost = "distributed_ghost";
// DFSPH's candidate masks (ParticleArrays::dfsph_neighbor_mask; Scratch, kNeighborMaskWords
// uint32 a particle).
constexpr const char* kArrayDfsphNeighborMask = "dfsph_neighbor_mask";
// DFSPH's neighbour lists (ParticleArrays::dfsph_neighbor_list; Scratch, kNeighborListRows uint32
// a particle, laid out slot-major).
constexpr const char* kArrayDfsphNeighborList = "dfsph_neighbor_list";

// A method's array on the device: its elements (two sides for a Sorted array) and, for a
// Carried one, the snapshot of the frame's start.
struct DeviceMethodArray {
  ParticleArraySpec spec;
  DeviceArray<unsigned char> side[2];
  DeviceArray<unsigned char> snapshot;
  uint64_t elements = 0;  // of each side: capacity * elements_per_particle, or 1 for a world word

  // Bytes of the first n particles (a world word: its one element).
  uint64_t bytes_for(uint32_t n) const {
    return static_cast<uint64_t>(spec.element_size) *
           (spec.elements_per_particle == 0 ? 1u : static_cast<uint64_t>(n) * spec.elements_per_particle);
  }
};

// The radix sort's buffers inside sorted_velocity: four uint32 arrays of `capacity` each.
struct SortScratch {
  uint32_t* keys[2];
  uint32_t* values[2];
};

class DeviceParticleStore {
 public:
  DeviceParticleStore(uint32_t capacity, const std::vector<ParticleArraySpec>& method_arrays);

  const ParticleArrays& arrays() const { return arrays_; }
  const HostVector<std::unique_ptr<DeviceMethodArray>>& method_arrays() const { return methods_; }
  // A method array's side (0 or 1) by name; null when the world has no such array.
  void* find(const char* name, int side = 0) const;
  SortScratch sort_scratch() const;
  uint32_t capacity() const { return capacity_; }

  // Copies the state of particles [0, n), the core's and the Carried arrays', into the
  // snapshot, and back.
  void enqueue_snapshot(uint32_t n, cudaStream_t stream) const;
  void enqueue_restore(uint32_t n, cudaStream_t stream) const;
  // Sets the methods' world words (and their snapshots) to their initial values (a new world).
  void enqueue_initial_world_words(cudaStream_t stream) const;
  // Copies the state of particles [0, n) of `from` (a smaller store of the same arrays: a world
  // that grows), the core's and the Carried arrays' with their snapshots, world words
  // included. What is not carried is rebuilt by every substep, as after a checkpoint load.
  void enqueue_copy_from(const DeviceParticleStore& from, uint32_t n, cudaStream_t stream) const;

  uint64_t bytes() const;

 private:
  uint32_t capacity_;
  DeviceArray<Float4> position_, velocity_, sorted_position_, sorted_velocity_;
  DeviceArray<uint32_t> id_, sorted_id_;
  DeviceArray<float> density_;
  DeviceArray<Float4> snapshot_position_, snapshot_velocity_;
  DeviceArray<uint32_t> snapshot_id_;
  DeviceArray<float> snapshot_density_;
  HostVector<std::unique_ptr<DeviceMethodArray>> methods_;
  ParticleArrays arrays_{};
};

}  // namespace sph
