// SPDX-License-Identifier: MIT
// A distributed world's slabs (src/core/slab_decomposition.h): who owns a cell layer, who needs
// it as a ghost, when the ranks are out of balance, and where a rebalance cuts. Every expected
// value is worked out by hand from the histogram, or (the rules the CUDA rank runs per particle,
// core/slab_rules.h) by brute force over every layer.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <random>
#include <vector>

#include "core/slab_decomposition.h"
#include "core/slab_rules.h"

namespace {

using sph::SlabDecomposition;

// Before any cut, rank 0 owns every layer and nobody needs ghosts.
void test_uncut(void**) {
  const SlabDecomposition s(3);
  assert_int_equal(s.ranks(), 3);
  assert_int_equal(s.owner(-1000), 0);
  assert_int_equal(s.owner(1 << 30), 0);
  int to[2];
  assert_int_equal(s.ghost_destinations(5, 0, to), 0);
}

// Layers 10..19 holding 1, 1, 1, 1, 4, 4, 1, 1, 1, 1 particles (16) over 4 ranks: the running
// count before layer k reaches 4 at layer 14, 8 at 15, 12 at 16: cuts 14, 15, 16.
void test_rebalance_cuts(void**) {
  SlabDecomposition s(4);
  s.rebalance(2, 10, {1, 1, 1, 1, 4, 4, 1, 1, 1, 1});
  assert_int_equal(s.axis(), 2);
  const std::vector<int32_t> want{14, 15, 16};
  assert_true(s.cuts() == want);
  assert_int_equal(s.owner(-5), 0);
  assert_int_equal(s.owner(13), 0);
  assert_int_equal(s.owner(14), 1);
  assert_int_equal(s.owner(15), 2);
  assert_int_equal(s.owner(16), 3);
  assert_int_equal(s.owner(100), 3);
  // Layer 15 (rank 2) borders rank 1's 14 and rank 3's 16; layer 13 (rank 0) borders rank 1.
  int to[2];
  assert_int_equal(s.ghost_destinations(15, 2, to), 2);
  assert_int_equal(to[0], 1);
  assert_int_equal(to[1], 3);
  assert_int_equal(s.ghost_destinations(13, 0, to), 1);
  assert_int_equal(to[0], 1);
  assert_int_equal(s.ghost_destinations(12, 0, to), 0);
}

// More ranks than occupied layers: the last ranks own nothing (cut past the data).
void test_more_ranks_than_layers(void**) {
  SlabDecomposition s(4);
  s.rebalance(0, 0, {5, 5});
  // Targets 3, 5, 8: layer 0 (5) reaches 3 and 5 -> cuts 1, 1; layer 1 reaches 8 -> past the end.
  const std::vector<int32_t> want{1, 1, INT32_MAX};
  assert_true(s.cuts() == want);
  assert_int_equal(s.owner(0), 0);
  assert_int_equal(s.owner(1), 2);  // rank 1 owns [1, 1): nothing
  int to[2];
  assert_int_equal(s.ghost_destinations(0, 0, to), 1);  // layer 1 is rank 2's
  assert_int_equal(to[0], 2);
}

void test_imbalance(void**) {
  // Mean 10: 11 is 10 % above it, 13 is 30 %.
  assert_false(SlabDecomposition::imbalanced({9, 10, 11}, 0.2));
  assert_true(SlabDecomposition::imbalanced({7, 10, 13}, 0.2));
  assert_false(SlabDecomposition::imbalanced({0, 0}, 0.2));
}

// The rules as the device runs them (slab_owner's binary search) against their definitions by
// brute force: the owner is the number of cuts at or below the layer (rank r owns [cut r-1,
// cut r)); the ghosts' ranks are the other owners of the layers beside it, each once, ascending.
// Random cuts with repeats (ranks owning nothing), 1 to 6 ranks, layers around and at the cuts
// and at the int32 ends.
void test_rules_brute_force(void**) {
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 2000; ++trial) {
    const int ranks = 1 + static_cast<int>(rng() % 6);
    std::vector<int32_t> cuts(static_cast<size_t>(ranks - 1));
    for (int32_t& c : cuts) c = static_cast<int32_t>(rng() % 12) - 6;
    if (!cuts.empty() && rng() % 4 == 0) cuts.back() = INT32_MAX;
    std::sort(cuts.begin(), cuts.end());
    const int count = static_cast<int>(cuts.size());
    auto brute_owner = [&](int64_t layer) {
      int o = 0;
      for (int32_t c : cuts) o += c <= layer ? 1 : 0;
      return o;
    };
    std::vector<int32_t> layers{INT32_MIN, INT32_MIN + 1, INT32_MAX - 1, INT32_MAX};
    for (int32_t l = -9; l <= 9; ++l) layers.push_back(l);
    for (int32_t layer : layers) {
      assert_int_equal(sph::slab_owner(cuts.data(), count, layer), brute_owner(layer));
      for (int self = 0; self < ranks; ++self) {
        std::vector<int> want;
        for (int64_t beside : {static_cast<int64_t>(layer) - 1, static_cast<int64_t>(layer) + 1}) {
          if (beside < INT32_MIN || beside > INT32_MAX) continue;
          const int o = brute_owner(beside);
          if (o != self && std::find(want.begin(), want.end(), o) == want.end()) want.push_back(o);
        }
        std::sort(want.begin(), want.end());
        int got[2] = {-1, -1};
        const int n = sph::slab_ghost_destinations(cuts.data(), count, layer, self, got);
        assert_int_equal(n, static_cast<int>(want.size()));
        for (int k = 0; k < n; ++k) assert_int_equal(got[k], want[static_cast<size_t>(k)]);
      }
    }
  }
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uncut),
      cmocka_unit_test(test_rebalance_cuts),
      cmocka_unit_test(test_more_ranks_than_layers),
      cmocka_unit_test(test_imbalance),
      cmocka_unit_test(test_rules_brute_force),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
