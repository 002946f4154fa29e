// SPDX-License-Identifier: MIT
#include "slab_decomposition.h"

#include <algorithm>

#include "slab_rules.h"
#include "status.h"

namespace sph {

namespace {

// (INT32_MAX too: the cut after every particle, and the end of the clamped far layers.)
bool on_layer_boundary(int64_t sub) { return sub % kSlabSubLayers == 0 || sub == INT32_MAX; }

// A slab between the first and the last that keeps every particle's ghost destinations at two
// (slab_rules.h).
bool middle_slab_allowed(int64_t begin, int64_t end) {
  const int64_t width = end - begin;
  return width == 0 || width >= kSlabMinWidth || (on_layer_boundary(begin) && on_layer_boundary(end));
}

int64_t layer_of_sub(int64_t sub) {
  return sub >= 0 ? sub / kSlabSubLayers : -((-sub + kSlabSubLayers - 1) / kSlabSubLayers);
}

}  // namespace

SlabDecomposition::SlabDecomposition(int ranks)
    : cuts_(static_cast<size_t>(ranks > 1 ? ranks - 1 : 0), INT32_MAX) {}

int SlabDecomposition::owner(int32_t sub) const {
  return slab_owner(cuts_.data(), static_cast<int>(cuts_.size()), sub);
}

int SlabDecomposition::ghost_destinations(int32_t layer, int self, int out[2]) const {
  return slab_ghost_destinations(cuts_.data(), static_cast<int>(cuts_.size()), layer, self, out);
}

int64_t SlabDecomposition::begin(int r) const {
  return slab_begin(cuts_.data(), static_cast<int>(cuts_.size()), r);
}

int64_t SlabDecomposition::end(int r) const {
  return slab_end(cuts_.data(), static_cast<int>(cuts_.size()), r);
}

void SlabDecomposition::describe(int r, DistributedCounters& c) const {
  c.axis = axis_;
  const int64_t b = begin(r), e = end(r);
  if (b >= e) {
    c.slab_first = c.sub_first = 0;
    c.slab_last = c.sub_last = -1;
    return;
  }
  const bool first = r == 0, last = r == ranks() - 1;
  c.sub_first = first ? INT32_MIN : static_cast<int32_t>(b);
  c.sub_last = last ? INT32_MAX : static_cast<int32_t>(e - 1);
  c.slab_first = first ? INT32_MIN : static_cast<int32_t>(layer_of_sub(b));
  c.slab_last = last ? INT32_MAX : static_cast<int32_t>(layer_of_sub(e - 1));
}

bool SlabDecomposition::imbalanced(const std::vector<int64_t>& count, double threshold) {
  if (count.empty()) return false;
  int64_t total = 0, fullest = 0;
  for (int64_t c : count) {
    total += c;
    fullest = std::max(fullest, c);
  }
  const double mean = static_cast<double>(total) / static_cast<double>(count.size());
  return static_cast<double>(fullest) > (1.0 + threshold) * mean;
}

namespace {

// Walks the cuts' targets over a histogram of particles per layer: visit(r, k, before, target)
// for cut r (1 .. ranks - 1) with k the histogram's index of the layer where the running count
// reaches ceil(r * total / ranks) (histogram.size(): never) and `before` the count of the layers
// below it.
template <class Visit>
void walk_targets(int ranks, const std::vector<int64_t>& histogram, Visit&& visit) {
  int64_t total = 0;
  for (int64_t c : histogram) total += c;
  int64_t before = 0;
  size_t k = 0;
  for (int r = 1; r < ranks; ++r) {
    const int64_t target = (total * r + ranks - 1) / ranks;
    while (k < histogram.size() && before + histogram[k] < target) before += histogram[k++];
    visit(r, k, before, target);
  }
}

}  // namespace

std::vector<int32_t> SlabDecomposition::crossing_layers(int ranks, int32_t first_layer,
                                                        const std::vector<int64_t>& histogram) {
  std::vector<int32_t> layers(static_cast<size_t>(ranks > 1 ? ranks - 1 : 0), INT32_MAX);
  walk_targets(ranks, histogram, [&](int r, size_t k, int64_t, int64_t) {
    if (k < histogram.size()) layers[static_cast<size_t>(r - 1)] = first_layer + static_cast<int32_t>(k);
  });
  return layers;
}

void SlabDecomposition::rebalance(int axis, int32_t first_layer, const std::vector<int64_t>& histogram,
                                  const std::vector<int64_t>& sixteenths) {
  const int n = ranks();
  if (sixteenths.size() != static_cast<size_t>(n - 1) * kSlabSubLayers)
    throw Error(Status::Internal, "slabs: sixteenths for another number of ranks");
  // Each cut at the first sub-layer of its crossing layer that the lower ranks do not take (cuts),
  // and the same cut at the layer's end where the rest of the layer is empty (at_end): both split
  // the same particles, and the layer's end leaves both neighbours the smaller halo (a slab that
  // meets a layer in part takes the rest of it as ghosts).
  std::vector<int32_t> cuts(static_cast<size_t>(n - 1), INT32_MAX), at_end(cuts);
  walk_targets(n, histogram, [&](int r, size_t k, int64_t before, int64_t target) {
    if (k >= histogram.size()) return;
    const int64_t* mine = sixteenths.data() + static_cast<size_t>(r - 1) * kSlabSubLayers;
    int j = 0;
    for (int64_t running = before; j < kSlabSubLayers && running < target;) running += mine[j++];
    int empty_to = j;
    while (empty_to < kSlabSubLayers && mine[empty_to] == 0) ++empty_to;
    const int32_t layer = first_layer + static_cast<int32_t>(k);
    cuts[static_cast<size_t>(r - 1)] = slab_sublayer(layer, j);
    at_end[static_cast<size_t>(r - 1)] =
        slab_sublayer(layer, empty_to == kSlabSubLayers ? kSlabSubLayers : j);
  });
  if (valid(n, axis, cuts)) {
    // A cut moves to its layer's end only where both slabs beside it stay allowed (moving it up
    // narrows the slab above, and may make the one below a thin slab that is not whole layers); the
    // slab above is checked against the next cut before its own move, which can only widen it.
    for (size_t c = 0; c < cuts.size(); ++c) {
      if (at_end[c] == cuts[c]) continue;
      const bool below_ok = c == 0 || middle_slab_allowed(cuts[c - 1], at_end[c]);
      const bool above_ok = c + 1 >= cuts.size() || middle_slab_allowed(at_end[c], cuts[c + 1]);
      if (below_ok && above_ok && at_end[c] <= (c + 1 < cuts.size() ? cuts[c + 1] : INT32_MAX))
        cuts[c] = at_end[c];
    }
  } else {
    // Slabs thinner than one and a half layers: whole layers, each cut after its crossing layer
    // (INT32_MAX after the last one), as before sub-layers.
    walk_targets(n, histogram, [&](int r, size_t k, int64_t, int64_t) {
      cuts[static_cast<size_t>(r - 1)] =
          k + 1 < histogram.size() ? slab_sublayer(first_layer + static_cast<int32_t>(k + 1), 0) : INT32_MAX;
    });
  }
  axis_ = axis;
  cuts_ = cuts;
}

bool SlabDecomposition::valid(int ranks, int axis, const std::vector<int32_t>& cuts) {
  if (ranks < 1 || axis < 0 || axis > 2) return false;
  if (cuts.size() != static_cast<size_t>(ranks - 1)) return false;
  if (!std::is_sorted(cuts.begin(), cuts.end())) return false;
  for (size_t r = 1; r < cuts.size(); ++r)
    if (!middle_slab_allowed(cuts[r - 1], cuts[r])) return false;
  return true;
}

void SlabDecomposition::restore(int axis, const std::vector<int32_t>& cuts) {
  if (!valid(ranks(), axis, cuts)) throw Error(Status::Internal, "slabs: an invalid decomposition");
  axis_ = axis;
  cuts_ = cuts;
}

}  // namespace sph
