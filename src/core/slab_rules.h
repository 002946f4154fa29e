// SPDX-License-Identifier: MIT
// The slabs' rules on one particle, for host and device code alike (one copy of each): its cell
// layer along the slabs' axis, the rank that owns a layer, and the ranks that need a layer's
// particles as ghosts. SlabDecomposition (slab_decomposition.h) answers with these on the host;
// the CUDA rank (cuda/device_halo.cu) runs them per particle on the device, where the cuts are a
// device copy of SlabDecomposition::cuts(): `count` ascending cuts, rank r owning the layers
// [cuts[r - 1], cuts[r]) (cuts[-1] = -inf, cuts[count] = +inf).
#pragma once

#include <stdint.h>

#include "../physics/grid_hash.h"
#include "../physics/host_device.h"

namespace sph {

// Cell layer of a point along `axis`.
SPH_HD int32_t slab_layer(float x, float y, float z, int axis, float inv_cell_size) {
  return cell_coordinate(axis == 0 ? x : (axis == 1 ? y : z), inv_cell_size);
}

// The rank that owns `layer`: the index of the first cut above it (std::upper_bound's answer).
SPH_HD int slab_owner(const int32_t* cuts, int count, int32_t layer) {
  int lo = 0, hi = count;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (cuts[mid] > layer)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// The owners of the layers beside `layer` that are not `self` (0, 1 or 2 ranks, in rank order)
// into out: the ranks that need a particle of this layer as a ghost. Returns how many.
SPH_HD int slab_ghost_destinations(const int32_t* cuts, int count, int32_t layer, int self, int out[2]) {
  int n = 0;
  const int below = layer > INT32_MIN ? slab_owner(cuts, count, layer - 1) : self;
  const int above = layer < INT32_MAX ? slab_owner(cuts, count, layer + 1) : self;
  if (below != self) out[n++] = below;
  if (above != self && above != below) out[n++] = above;
  if (n == 2 && out[0] > out[1]) {
    const int t = out[0];
    out[0] = out[1];
    out[1] = t;
  }
  return n;
}

}  // namespace sph
