// SPDX-License-Identifier: MIT
// The domain decomposition of a distributed world: slabs of whole grid cells along one axis.
// Rank r owns the cell layers [cut[r], cut[r + 1]) along `axis` (cut[0] = -inf, cut[size] =
// +inf; a rank may own none), so every cell, and with it every neighbour walk's cell, has one
// owner. A rank's ghosts (halo) are the particles of the layer on each side of its slab: one
// cell, one support radius, deep. Rebalancing moves the cuts so that each rank owns about the
// same number of particles, in whole layers.
#pragma once

#include <stdint.h>

#include <vector>

namespace sph {

class SlabDecomposition {
 public:
  // One slab, rank 0 owning everything, until the first rebalance.
  explicit SlabDecomposition(int ranks = 1);

  int ranks() const { return static_cast<int>(cuts_.size()) + 1; }
  int axis() const { return axis_; }
  // The rank that owns cell layer `layer`.
  int owner(int32_t layer) const;
  // The owners of the layers beside `layer` that are not `self` (0, 1 or 2 ranks, in rank
  // order): the ranks that need a particle of this layer as a ghost.
  int ghost_destinations(int32_t layer, int self, int out[2]) const;
  // Particles per rank are count[r]: whether the fullest rank holds more than (1 + threshold)
  // times the mean.
  static bool imbalanced(const std::vector<int64_t>& count, double threshold);
  // New cuts along `axis` from a histogram of particles per layer (layer first_layer + k holds
  // histogram[k]): rank r's slab starts at the first layer where the running count passes
  // r / ranks of the total.
  void rebalance(int axis, int32_t first_layer, const std::vector<int64_t>& histogram);
  const std::vector<int32_t>& cuts() const { return cuts_; }
  // Cuts as cuts() gave them (a checkpoint's): ranks() - 1 of them, non-decreasing, axis 0-2.
  // Whether `axis` and `cuts` are such a decomposition for `ranks` ranks.
  static bool valid(int ranks, int axis, const std::vector<int32_t>& cuts);
  // Takes a valid decomposition (Internal otherwise).
  void restore(int axis, const std::vector<int32_t>& cuts);

 private:
  int axis_ = 0;
  std::vector<int32_t> cuts_;  // ranks - 1 ascending cuts: rank r owns [cuts_[r-1], cuts_[r])
};

}  // namespace sph
