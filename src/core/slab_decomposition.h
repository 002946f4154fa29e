// SPDX-License-Identifier: MIT
// The domain decomposition of a distributed world: slabs along one axis, in sub-layers (a
// sixteenth of a cell layer; slab_rules.h). Rank r owns the sub-layers [cut[r], cut[r + 1])
// along `axis` (cut[0] = -inf, cut[size] = +inf; a rank may own none), so every particle has one
// owner. A rank's ghosts (halo) are the particles it does not own in the layers its slab meets
// and the layer on each side of them: one cell, one support radius, deep. Rebalancing moves the
// cuts so that each rank owns about the same number of particles, to a sixteenth of a layer.
#pragma once

#include <stdint.h>

#include <vector>

#include "distributed.h"

namespace sph {

class SlabDecomposition {
 public:
  // One slab, rank 0 owning everything, until the first rebalance.
  explicit SlabDecomposition(int ranks = 1);

  int ranks() const { return static_cast<int>(cuts_.size()) + 1; }
  int axis() const { return axis_; }
  // The rank that owns sub-layer `sub` (slab_position).
  int owner(int32_t sub) const;
  // The ranks other than `self` whose slabs meet the layers beside and at `layer` (0, 1 or 2
  // ranks, in rank order): the ranks that need a particle of this layer as a ghost.
  int ghost_destinations(int32_t layer, int self, int out[2]) const;
  // Rank r's slab, the sub-layers [begin(r), end(r)) (empty when begin >= end).
  int64_t begin(int r) const;
  int64_t end(int r) const;
  // Rank r's slab as sph_mpi_counts reports it (axis, slab_first/last, sub_first/last).
  void describe(int r, DistributedCounters& c) const;
  // Particles per rank are count[r]: whether the fullest rank holds more than (1 + threshold)
  // times the mean.
  static bool imbalanced(const std::vector<int64_t>& count, double threshold);
  // The cuts' layers for a histogram of particles per layer (layer first_layer + k holds
  // histogram[k]) over `ranks` ranks: cut r (of ranks - 1) falls in the layer where the running
  // count reaches ceil(r * total / ranks).
  static std::vector<int32_t> crossing_layers(int ranks, int32_t first_layer,
                                              const std::vector<int64_t>& histogram);
  // New cuts along `axis`: cut r (1 .. ranks - 1) is the first sub-layer of its crossing layer
  // where the running count reaches its target, counted with sixteenths[16 (r - 1) + j], the
  // particles of that layer's sixteenth j (the layer's end when the rest of it is empty). Where
  // a slab between the first and the last would be narrower than kSlabMinWidth, every cut is a
  // whole layer instead (the layer after its crossing layer; INT32_MAX after the last layer),
  // which keeps the decomposition valid.
  void rebalance(int axis, int32_t first_layer, const std::vector<int64_t>& histogram,
                 const std::vector<int64_t>& sixteenths);
  const std::vector<int32_t>& cuts() const { return cuts_; }
  // Whether `axis` and `cuts` are a decomposition for `ranks` ranks: ranks() - 1 non-decreasing
  // cuts, axis 0-2, each slab between the first and the last empty, at least kSlabMinWidth wide,
  // or from a layer boundary to a layer boundary (slab_rules.h: a particle then has at most two
  // ghost destinations).
  static bool valid(int ranks, int axis, const std::vector<int32_t>& cuts);
  // Takes a valid decomposition (Internal otherwise).
  void restore(int axis, const std::vector<int32_t>& cuts);

 private:
  int axis_ = 0;
  std::vector<int32_t> cuts_;  // ranks - 1 ascending cuts: rank r owns [cuts_[r-1], cuts_[r])
};

}  // namespace sph
