// SPDX-License-Identifier: MIT
// The slabs' rules on one particle, for host and device code alike (one copy of each): its cell
// layer and its sub-layer along the slabs' axis, the rank that owns a sub-layer, and the ranks
// that need a layer's particles as ghosts. SlabDecomposition (slab_decomposition.h) answers with
// these on the host; the CUDA rank (cuda/device_halo_lists.cu) runs them per particle on the
// device, where the cuts are a device copy of SlabDecomposition::cuts(): `count` ascending cuts
// in sub-layers, rank r owning the sub-layers [cuts[r - 1], cuts[r]) (cuts[-1] = -inf,
// cuts[count] = +inf).
//
// Sub-layers: each cell layer k (floor(x / h) = k) is cut in kSlabSubLayers equal parts, and
// sub-layer 16 k + j holds its points whose fraction x / h - k lies in [j / 16, (j + 1) / 16)
// (clamped to [INT32_MIN, INT32_MAX - 1], which only the clamped far cells reach). A cut between
// two sub-layers of one layer balances the ranks to a sixteenth of a layer's particles instead of
// a whole layer's (issue 19: at 8 and 16 ranks whole layers left the fullest rank 14 % above the
// mean).
//
// The neighbour walk visits whole cells: a particle of layer k reads every particle of layers
// k - 1 .. k + 1, so the ranks whose slabs meet those three layers (other than its owner) need
// it as a ghost. A slab between the first and the last is empty, or at least kSlabMinWidth (one
// and a half layers) wide, or begins and ends at layer boundaries (a decomposition of whole
// layers, as manifests of version 1 hold): then three layers meet at most three slabs, and a
// particle has at most two ghost destinations (SlabDecomposition::valid; the unit test checks
// it by brute force).
#pragma once

#include <stdint.h>

#include "../physics/grid_hash.h"
#include "../physics/host_device.h"

namespace sph {

constexpr int kSlabSubLayers = 16;
constexpr int kSlabMinWidth = 24;  // sub-layers: one and a half layers

// A point's coordinate along the slabs' axis (0: x, 1: y, 2: z): the one place that picks it.
SPH_HD float slab_axis_coordinate(float x, float y, float z, int axis) {
  return axis == 0 ? x : (axis == 1 ? y : z);
}

// Cell layer of a point along `axis`.
SPH_HD int32_t slab_layer(float x, float y, float z, int axis, float inv_cell_size) {
  return cell_coordinate(slab_axis_coordinate(x, y, z, axis), inv_cell_size);
}

// Which sixteenth of its layer `layer` (cell_coordinate(v, inv)) coordinate v lies in, 0-15:
// the same product as cell_coordinate's, minus the layer (exact: the two are within one), in
// sixteenths (exact), floored and clamped (a clamped far cell, NaN: 0 or 15).
SPH_HD int slab_sixteenth(float v, float inv_cell_size, int32_t layer) {
  const float t = flushed_to_zero(flushed_to_zero(v) * inv_cell_size);
  float f = SPH_FLOORF((t - static_cast<float>(layer)) * static_cast<float>(kSlabSubLayers));
  f = SPH_FMINF(SPH_FMAXF(f, 0.0f), static_cast<float>(kSlabSubLayers - 1));
  return static_cast<int>(f);
}

// Sub-layer j of layer `layer` (int64 arithmetic, clamped to [INT32_MIN, INT32_MAX - 1]: INT32_MAX
// is no sub-layer, only the cut past every particle, so a rank whose slab begins there owns none;
// j may be -16 .. 31 to name the layers beside).
SPH_HD int32_t slab_sublayer(int32_t layer, int j) {
  const int64_t s = static_cast<int64_t>(layer) * kSlabSubLayers + j;
  return s < INT32_MIN ? INT32_MIN : (s > INT32_MAX - 1 ? INT32_MAX - 1 : static_cast<int32_t>(s));
}

// Sub-layer of a point along `axis`: what ownership reads.
SPH_HD int32_t slab_position(float x, float y, float z, int axis, float inv_cell_size) {
  const float v = slab_axis_coordinate(x, y, z, axis);
  const int32_t layer = cell_coordinate(v, inv_cell_size);
  return slab_sublayer(layer, slab_sixteenth(v, inv_cell_size, layer));
}

// The rank that owns sub-layer `sub`: the index of the first cut above it (std::upper_bound's
// answer).
SPH_HD int slab_owner(const int32_t* cuts, int count, int32_t sub) {
  int lo = 0, hi = count;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (cuts[mid] > sub)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// Rank r's slab, the sub-layers [slab_begin, slab_end) (the outer ranks reach INT32_MIN and
// INT32_MAX, past the last sub-layer; empty when begin >= end).
SPH_HD int64_t slab_begin(const int32_t* cuts, int count, int r) {
  (void)count;
  return r == 0 ? int64_t{INT32_MIN} : cuts[r - 1];
}
SPH_HD int64_t slab_end(const int32_t* cuts, int count, int r) {
  return r == count ? int64_t{INT32_MAX} : cuts[r];
}

// The ranks other than `self` whose slabs meet the layers layer - 1 .. layer + 1 (0, 1 or 2 of
// them for a valid decomposition, in rank order) into out: the ranks that need a particle of
// this layer as a ghost. Returns how many (at most 2: see above).
SPH_HD int slab_ghost_destinations(const int32_t* cuts, int count, int32_t layer, int self, int out[2]) {
  const int first = slab_owner(cuts, count, slab_sublayer(layer, -kSlabSubLayers));
  const int last = slab_owner(cuts, count, slab_sublayer(layer, 2 * kSlabSubLayers - 1));
  int n = 0;
  for (int r = first; r <= last && n < 2; ++r)
    if (r != self && slab_begin(cuts, count, r) < slab_end(cuts, count, r)) out[n++] = r;
  return n;
}

}  // namespace sph
