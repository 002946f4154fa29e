// SPDX-License-Identifier: MIT
#include "slab_decomposition.h"

#include <algorithm>

#include "slab_rules.h"
#include "status.h"

namespace sph {

SlabDecomposition::SlabDecomposition(int ranks)
    : cuts_(static_cast<size_t>(ranks > 1 ? ranks - 1 : 0), INT32_MAX) {}

int SlabDecomposition::owner(int32_t layer) const {
  return slab_owner(cuts_.data(), static_cast<int>(cuts_.size()), layer);
}

int SlabDecomposition::ghost_destinations(int32_t layer, int self, int out[2]) const {
  return slab_ghost_destinations(cuts_.data(), static_cast<int>(cuts_.size()), layer, self, out);
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

void SlabDecomposition::rebalance(int axis, int32_t first_layer, const std::vector<int64_t>& histogram) {
  axis_ = axis;
  const int n = ranks();
  int64_t total = 0;
  for (int64_t c : histogram) total += c;
  std::vector<int32_t> cuts(static_cast<size_t>(n - 1), INT32_MAX);
  int64_t running = 0;
  size_t k = 0;
  for (int r = 1; r < n; ++r) {
    // The smallest layer whose running count (layers before it) reaches r * total / n.
    const int64_t target = (total * r + n - 1) / n;
    while (k < histogram.size() && running < target) running += histogram[k++];
    cuts[static_cast<size_t>(r - 1)] =
        k < histogram.size() ? first_layer + static_cast<int32_t>(k) : INT32_MAX;
  }
  cuts_ = cuts;
}

bool SlabDecomposition::valid(int ranks, int axis, const std::vector<int32_t>& cuts) {
  if (ranks < 1 || axis < 0 || axis > 2) return false;
  if (cuts.size() != static_cast<size_t>(ranks - 1)) return false;
  return std::is_sorted(cuts.begin(), cuts.end());
}

void SlabDecomposition::restore(int axis, const std::vector<int32_t>& cuts) {
  if (!valid(ranks(), axis, cuts)) throw Error(Status::Internal, "slabs: an invalid decomposition");
  axis_ = axis;
  cuts_ = cuts;
}

}  // namespace sph
