// SPDX-License-Identifier: MIT
// The frame's start of a distributed world's rank (include/sph_mpi.h), the same for every
// backend (src/cpu/cpu_halo.cpp, cuda/cuda_halo.cu): when the slabs were never cut or the
// fullest rank holds too many particles, new cuts along the longest axis of the world's extent
// in cells, from a histogram of particles per cell layer and one of the sixteenths of each layer
// a cut falls in (SlabDecomposition::rebalance). The particles' layer and sub-layer along the
// slabs' axis, which every migration and ghost decision reads, are in slab_rules.h.
#pragma once

#include <stdint.h>

#include <algorithm>
#include <vector>

#include "../physics/grid_hash.h"
#include "rank_agreement.h"
#include "slab_decomposition.h"
#include "slab_rules.h"

namespace sph {

// COLLECTIVE, after an agreement. held: ranks() entries, allocated by the caller before that
// agreement (nothing here allocates before the first reduction, so a rank that fails cannot be
// in another collective than the rest). position_of(i) gives a record with x, y, z for each of
// the rank's `count` particles. Returns whether the slabs were cut anew.
template <class PositionOf>
bool rebalance_slabs(const RankTransport& t, SlabDecomposition& slabs, bool already_cut, double threshold,
                     uint32_t count, float inv_cell_size, std::vector<int64_t>& held,
                     PositionOf&& position_of) {
  std::fill(held.begin(), held.end(), 0);
  held[static_cast<size_t>(t.rank())] = count;
  t.all_sum(held.data(), t.size());
  if (already_cut && !SlabDecomposition::imbalanced(held, threshold)) return false;
  int64_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  for (uint32_t i = 0; i < count; ++i) {
    const auto p = position_of(i);
    const float x[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
      const int64_t c = cell_coordinate(x[a], inv_cell_size);
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
  t.all_min(lo, 3);
  t.all_max(hi, 3);
  if (lo[0] > hi[0]) return false;  // no particles anywhere: nothing to cut
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  // (A failed allocation here meets the others at the agreement below, from the step's catch.)
  std::vector<int64_t> histogram(static_cast<size_t>(hi[axis] - lo[axis] + 1), 0);
  for (uint32_t i = 0; i < count; ++i) {
    const auto p = position_of(i);
    ++histogram[static_cast<size_t>(slab_layer(p.x, p.y, p.z, axis, inv_cell_size) - lo[axis])];
  }
  agree(t);  // (the histogram's allocation)
  t.all_sum(histogram.data(), static_cast<int>(histogram.size()));
  // The layers the cuts fall in, each cut into sixteenths (slab_rules.h): a second sum of 16
  // counts a cut. The crossing layers ascend, so each particle finds the first cut of its layer
  // by a binary search and counts there; cuts in one layer share its counts.
  const int32_t first_layer = static_cast<int32_t>(lo[axis]);
  const std::vector<int32_t> crossing = SlabDecomposition::crossing_layers(t.size(), first_layer, histogram);
  std::vector<int64_t> sixteenths(crossing.size() * kSlabSubLayers, 0);
  for (uint32_t i = 0; i < count && !crossing.empty(); ++i) {
    const auto p = position_of(i);
    const float v = slab_axis_coordinate(p.x, p.y, p.z, axis);
    const int32_t layer = cell_coordinate(v, inv_cell_size);
    const auto at = std::lower_bound(crossing.begin(), crossing.end(), layer);
    if (at == crossing.end() || *at != layer) continue;
    const size_t cut = static_cast<size_t>(at - crossing.begin());
    ++sixteenths[cut * kSlabSubLayers + static_cast<size_t>(slab_sixteenth(v, inv_cell_size, layer))];
  }
  agree(t);  // (the sixteenths' allocation)
  if (!sixteenths.empty()) t.all_sum(sixteenths.data(), static_cast<int>(sixteenths.size()));
  for (size_t c = 1; c < crossing.size(); ++c)
    if (crossing[c] == crossing[c - 1])
      std::copy_n(sixteenths.begin() + static_cast<std::ptrdiff_t>((c - 1) * kSlabSubLayers), kSlabSubLayers,
                  sixteenths.begin() + static_cast<std::ptrdiff_t>(c * kSlabSubLayers));
  slabs.rebalance(axis, first_layer, histogram, sixteenths);
  return true;
}

}  // namespace sph
