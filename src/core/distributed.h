// SPDX-License-Identifier: MIT
// A distributed world's options and counters (include/sph_mpi.h; the backend's halo steps,
// src/cpu/cpu_halo.cpp), apart from the transport (rank_transport.h) that carries them.
#pragma once

#include <stdint.h>

#include <vector>

namespace sph {

// Each particle's sort key in a distributed world (cpu_halo.cpp): a carried array that a rank's
// checkpoint saves with its particles.
constexpr const char* kArrayDistributedSortKey = "distributed_sort_key";
// The key of a particle appended since the last sort (ored with its id): after every sorted
// one, in id order (the undivided world appends at the end, ids ascending).
constexpr uint64_t kAppendedSortKey = 0xffffffff00000000ull;

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
  int32_t slab_first = 0;     // the cell layers this rank's slab meets [slab_first, slab_last]
  int32_t slab_last = 0;      // (empty: first > last; SlabDecomposition::describe)
  int32_t sub_first = 0;      // its sub-layers [sub_first, sub_last] (slab_rules.h)
  int32_t sub_last = 0;
};

// A CPU rank's hash+sort stage in its parts (bench/mpi_halo; issue 19): wall ms since the world was
// made, the transport's calls included, so that a slow stage on a many-rank host can be traced
// without a profiler.
enum HaloPhase : int {
  kHaloMigrate,  // migrants classified, packed, exchanged; the kept compacted, the arrivals unpacked
  kHaloGhosts,   // ghosts classified, packed, exchanged, unpacked
  kHaloSprings,  // spring partners and spring ghosts
  kHaloExtent,   // the owned and held extents, the world's reductions, the tables' shapes
  kHaloVisit,    // the sort's visit order (the merge of the arrival runs)
  kHaloGrid,     // the grid's counting sort over the rank's table
  kHaloReorder,  // the store's permutation into the grid's order
  kHaloKeys,     // the sort keys
  kHaloPhaseCount
};
struct HaloPhaseTimes {
  double ms[kHaloPhaseCount] = {};
};

// What a rank's checkpoint carries beside its particles: the decomposition and the counters, so
// that a restored world cuts, migrates and counts as the saved one would have.
struct DistributedState {
  int32_t axis = 0;                  // the slabs' axis
  std::vector<int32_t> cuts;         // ranks - 1 cuts in sub-layers (SlabDecomposition::cuts)
  bool cut = false;                  // whether the first frame's cut was made
  DistributedCounters counters;      // ghosts, migrated_in, migrated_out, rebalances (axis and slab: above)
  double rebalance_threshold = 0.2;  // DistributedOptions' (reported; attach_ranks sets it)
};

}  // namespace sph
