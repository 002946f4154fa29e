// SPDX-License-Identifier: MIT
// The CPU rank's sort order (cpu_rank_halo.h, order_visits): its particles by sort key, then id,
// the order in which the grid's counting sort takes them (cpu_halo.cpp's gather calls it).
#include <algorithm>

#include "cpu_backend_impl.h"

namespace sph {

void CpuRankHalo::order_visits() {
  // The sort's order: by key, then id (two keys are equal only where the table folds). The
  // particles arrive as a few runs already in that order: the kept owned ones (in the last sort's
  // order, whose keys after_sort numbered), then each rank's migrants and each rank's ghosts (in
  // their sender's order). Merging the runs gives the order a sort would (key and id together are
  // unique, so the order is the one sorted order) in linear time, where the sort took n log n: about 1 ms of
  // a 40 ms substep at 84,672 particles on one rank of the development VM, and as much on each of two ranks
  // (session 36). Many runs (the first substep, a rebalance) sort instead.
  visit_.resize(count_);
  for (uint32_t i = 0; i < count_; ++i) visit_[i] = i;
  const uint64_t* key = sort_key_.data();
  const uint32_t* id = id_.data();
  const auto before = [key, id](uint32_t a, uint32_t b) {
    return key[a] != key[b] ? key[a] < key[b] : id[a] < id[b];
  };
  run_starts_.clear();
  for (uint32_t i = 1; i < count_ && run_starts_.size() <= kMergedRuns; ++i)
    if (before(i, i - 1)) run_starts_.push_back(i);
  if (run_starts_.size() > kMergedRuns) {
    std::sort(visit_.begin(), visit_.end(), before);
    return;
  }
  // Bottom-up: merge neighbouring runs into the other buffer until one is left (std::merge into
  // storage of our own: std::inplace_merge would take its buffer unseen, and go on without it
  // where that allocation fails, where every other allocation of a step fails the step).
  run_starts_.insert(run_starts_.begin(), 0u);
  run_starts_.push_back(count_);
  merged_.resize(count_);
  while (run_starts_.size() > 2) {
    size_t kept = 0;
    size_t r = 0;
    for (; r + 2 < run_starts_.size(); r += 2) {
      std::merge(visit_.begin() + run_starts_[r], visit_.begin() + run_starts_[r + 1],
                 visit_.begin() + run_starts_[r + 1], visit_.begin() + run_starts_[r + 2],
                 merged_.begin() + run_starts_[r], before);
      run_starts_[kept++] = run_starts_[r];
    }
    if (r + 1 < run_starts_.size()) {  // an odd run out: copied as it is
      std::copy(visit_.begin() + run_starts_[r], visit_.begin() + run_starts_[r + 1],
                merged_.begin() + run_starts_[r]);
      run_starts_[kept++] = run_starts_[r];
    }
    run_starts_[kept++] = count_;
    run_starts_.resize(kept);
    visit_.swap(merged_);
  }
}

}  // namespace sph
