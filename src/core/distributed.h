// SPDX-License-Identifier: MIT
// A distributed world's options and counters (include/sph_mpi.h; the backend's halo steps,
// src/cpu/cpu_halo.cpp), apart from the transport (rank_transport.h) that carries them.
#pragma once

#include <stdint.h>

namespace sph {

struct DistributedOptions {
  // Rebalance when the fullest rank holds more than (1 + threshold) times the mean.
  double rebalance_threshold = 0.2;
};

struct DistributedCounters {
  uint32_t ghosts = 0;        // halo particles this rank held in its last substep
  uint32_t migrated_in = 0;   // particles this rank received from others, summed over substeps
  uint32_t migrated_out = 0;  // particles this rank sent to others, summed over substeps
  uint32_t rebalances = 0;    // times the slabs were cut anew (the first cut counts)
  int32_t axis = 0;           // the slabs' axis (0 x, 1 y, 2 z)
  int32_t slab_first = 0;     // this rank's cell layers [slab_first, slab_last] (empty: first > last)
  int32_t slab_last = 0;
};

}  // namespace sph
