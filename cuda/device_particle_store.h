// The device-resident particle state of one world, as a structure of arrays, allocated once
// for the world's capacity:
//   position/velocity/id/density  the state in the current order (what callers read)
//   sorted_*                      the working copy in the order of the last sort; the density
//                                 pass reads it and the force pass writes the state from it.
//                                 sorted_velocity doubles as the radix sort's key/value
//                                 buffers, which are dead before the density pass fills it.
//   snapshot_*                    the state at the start of a frame, for the rollback
//   rk4_*                         RK4 worlds only: start state and slope sums, two sides
//   neighbor_count, normalized_density, colour_normal
//                                 per-substep side arrays of the physics options (Clavet
//                                 viscosity, normalised density, surface tension), allocated
//                                 only for a world that uses the option
//   springs, sorted_springs, ...  SPH_FEATURE_SPRINGS only (device_springs.h): the spring lists
//                                 in state order, their reordered working copy, the inverse
//                                 permutation, link candidates, spring accelerations, the
//                                 lowest id waiting for springs (one word), and snapshots
//   density_factor                normalised density's carried factor (state, in the current
//                                 order, with a snapshot), only for a world that uses it
// Float4 records carry a second quantity in w: position.w = pressure, velocity.w = 1/density.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/physics/float4_types.h"
#include "../src/physics/integrate.h"
#include "../src/physics/springs.h"
#include "device_array.h"

namespace sph {

// Raw pointers, passed by value into kernels.
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
};

// Which optional arrays a world needs.
struct StoreOptions {
  bool rk4 = false;
  bool neighbor_counts = false;
  bool normalized_density = false;
  bool colour_normals = false;
  bool springs = false;
};

// The radix sort's buffers inside sorted_velocity: four uint32 arrays of `capacity` each.
struct SortScratch {
  uint32_t* keys[2];
  uint32_t* values[2];
};

class DeviceParticleStore {
 public:
  DeviceParticleStore(uint32_t capacity, const StoreOptions& options);

  const ParticleArrays& arrays() const { return arrays_; }
  SortScratch sort_scratch() const;
  uint32_t capacity() const { return capacity_; }

  // Copies the state of particles [0, n) into the snapshot, and back.
  void enqueue_snapshot(uint32_t n, cudaStream_t stream) const;
  void enqueue_restore(uint32_t n, cudaStream_t stream) const;
  // Springs only: marks that no particle waits for springs (a new world).
  void enqueue_reset_link_state(cudaStream_t stream) const;

  uint64_t bytes() const;

 private:
  uint32_t capacity_;
  DeviceArray<Float4> position_, velocity_, sorted_position_, sorted_velocity_;
  DeviceArray<uint32_t> id_, sorted_id_;
  DeviceArray<float> density_;
  DeviceArray<Float4> snapshot_position_, snapshot_velocity_;
  DeviceArray<uint32_t> snapshot_id_;
  DeviceArray<float> snapshot_density_;
  DeviceArray<ParticleState> rk4_start_[2];
  DeviceArray<Rk4Accumulator> rk4_sum_[2];
  DeviceArray<uint32_t> neighbor_count_;
  DeviceArray<float> normalized_density_;
  DeviceArray<float> density_factor_, snapshot_density_factor_;
  DeviceArray<Float4> colour_normal_;
  DeviceArray<SpringList> springs_, sorted_springs_, snapshot_springs_;
  DeviceArray<uint32_t> spring_inverse_, spring_candidates_, link_from_, snapshot_link_from_;
  DeviceArray<Float4> spring_acceleration_;
  ParticleArrays arrays_{};
};

}  // namespace sph
