// SPDX-License-Identifier: MIT
// The frame's statistics, computed once at its end on the device: the density record
// (src/core/density_record.h) of the last density evaluation, and the neighbour counts of that evaluation
// (recounted here over the sorted copy it read, which is still intact, instead of being stored every
// substep).
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/density_record.h"
#include "../src/physics/fluid_constants.h"
#include "../src/physics/neighbor_walk.h"
#include "device_array.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

class FrameStatistics {
 public:
  explicit FrameStatistics(uint32_t capacity);
  // Writes density_* and neighbors_* of *state for particles [0, n). The neighbour counts are
  // recounted over the sorted copy, or read from `counts` when given (after a sink compaction,
  // which leaves the sorted copy behind). A distributed rank's last substep still holds its
  // `ghosts` (a.halo_ghost marks them): they are left out.
  void enqueue(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a, uint32_t n,
               FrameState* state, cudaStream_t stream, const uint32_t* counts = nullptr,
               uint32_t ghosts = 0) const;
  // counts[i] = the neighbour count of the last density pass of particle i (for a compaction).
  void enqueue_neighbor_counts(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, uint32_t* counts, cudaStream_t stream) const;
  uint64_t bytes() const { return partials_.bytes(); }

 private:
  DeviceArray<DensityTally> partials_;
};

}  // namespace sph
