// SPDX-License-Identifier: MIT
// A distributed world's slabs (src/core/slab_decomposition.h): who owns a sub-layer, who needs a
// layer's particles as ghosts, when the ranks are out of balance, and where a rebalance cuts.
// Every expected value is worked out by hand from the histograms, or (the rules the CUDA rank
// runs per particle, core/slab_rules.h) by brute force over every layer and rank.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/slab_decomposition.h"
#include "core/slab_rules.h"

namespace {

using sph::SlabDecomposition;

// Before any cut, rank 0 owns every sub-layer and nobody needs ghosts.
void test_uncut(void**) {
  const SlabDecomposition s(3);
  assert_int_equal(s.ranks(), 3);
  assert_int_equal(s.owner(-1000), 0);
  assert_int_equal(s.owner(1 << 30), 0);
  // The far end too: no sub-layer reaches INT32_MAX, the cut past every particle.
  assert_int_equal(s.owner(sph::slab_position(1e30f, 0.0f, 0.0f, 0, 1.0f)), 0);
  int to[2];
  assert_int_equal(s.ghost_destinations(5, 0, to), 0);
  assert_int_equal(s.ghost_destinations(1 << 30, 0, to), 0);
  sph::DistributedCounters c;
  s.describe(2, c);  // the last rank, whose slab begins at INT32_MAX: empty
  assert_true(c.sub_first > c.sub_last);
}

// A sub-layer is the layer's sixteenth: points at the middle of sixteenth j of layer k
// (h = 0.5: x = (16 k + j + 0.5) / 32, exact in float) sit in sub-layer 16 k + j, and the
// sub-layer never decreases with x and always lies in the point's cell layer.
void test_sub_layers(void**) {
  const float inv = 2.0f;
  for (int k = -40; k <= 40; ++k)
    for (int j = 0; j < sph::kSlabSubLayers; ++j) {
      const float x = static_cast<float>(16 * k + j) / 32.0f + 1.0f / 64.0f;
      assert_int_equal(sph::slab_position(x, 0.0f, 0.0f, 0, inv), 16 * k + j);
      assert_int_equal(sph::slab_position(0.0f, 0.0f, x, 2, inv), 16 * k + j);
    }
  std::mt19937 rng(7);
  std::vector<float> xs;
  for (int i = 0; i < 200000; ++i) {
    const float magnitude = std::ldexp(1.0f, static_cast<int>(rng() % 40) - 20);
    xs.push_back((static_cast<float>(rng()) / 4294967296.0f - 0.5f) * magnitude);
  }
  xs.push_back(0.0f);
  xs.push_back(-0.0f);
  xs.push_back(1e-40f);  // a denormal: flushed, as cell_coordinate does
  std::sort(xs.begin(), xs.end());
  int32_t previous = INT32_MIN;
  for (float x : xs) {
    const int32_t sub = sph::slab_position(x, 0.0f, 0.0f, 0, 3.7f);
    const int32_t layer = sph::cell_coordinate(x, 3.7f);
    assert_true(sub >= previous);
    const int64_t floor_div = sub >= 0 ? sub / 16 : -((-int64_t{sub} + 15) / 16);
    assert_int_equal(floor_div, layer);
    previous = sub;
  }
  // Far cells clamp without overflow, NaN goes where cell_coordinate sends it.
  assert_int_equal(sph::slab_position(1e30f, 0.0f, 0.0f, 0, 1.0f), INT32_MAX - 1);
  assert_int_equal(sph::slab_position(-1e30f, 0.0f, 0.0f, 0, 1.0f), INT32_MIN);
  assert_int_equal(sph::slab_position(std::nanf(""), 0.0f, 0.0f, 0, 1.0f), INT32_MIN);
}

// Layers 10..19 holding 4 particles each (40) over 4 ranks: targets 10, 20, 30. The running
// count reaches 10 in layer 12 (8 below it; its particles in sixteenths 1, 5, 9, 13: the second
// of them, in sixteenth 5, makes 10, so the cut is sub-layer 12 * 16 + 6), 20 in layer 14 (16
// below; sixteenths 0, 4, 8, 12: 20 at sixteenth 12, and the rest of the layer is empty, so the
// cut is the layer's end, 15 * 16: the same split, a layer less of halo) and 30 in layer 17 (28
// below; sixteenths 2, 2, 10, 10: cut 17 * 16 + 3). Middle slabs 42 and 35 sub-layers wide.
void test_rebalance_cuts(void**) {
  SlabDecomposition s(4);
  const std::vector<int64_t> histogram(10, 4);
  assert_true(SlabDecomposition::crossing_layers(4, 10, histogram) == (std::vector<int32_t>{12, 14, 17}));
  std::vector<int64_t> sixteenths(3 * 16, 0);
  for (int j : {1, 5, 9, 13}) ++sixteenths[0 * 16 + static_cast<size_t>(j)];
  for (int j : {0, 4, 8, 12}) ++sixteenths[1 * 16 + static_cast<size_t>(j)];
  for (int j : {2, 2, 10, 10}) ++sixteenths[2 * 16 + static_cast<size_t>(j)];
  s.rebalance(2, 10, histogram, sixteenths);
  assert_int_equal(s.axis(), 2);
  const std::vector<int32_t> want{12 * 16 + 6, 15 * 16, 17 * 16 + 3};
  assert_true(s.cuts() == want);
  assert_int_equal(s.owner(12 * 16 + 5), 0);
  assert_int_equal(s.owner(12 * 16 + 6), 1);
  assert_int_equal(s.owner(14 * 16 + 15), 1);
  assert_int_equal(s.owner(15 * 16), 2);
  assert_int_equal(s.owner(17 * 16 + 3), 3);
  // Layer 12 is shared by ranks 0 and 1: a particle there is a ghost of the other one, and of
  // nobody else (rank 2 begins in layer 14).
  int to[2];
  assert_int_equal(s.ghost_destinations(12, 0, to), 1);
  assert_int_equal(to[0], 1);
  assert_int_equal(s.ghost_destinations(12, 1, to), 1);
  assert_int_equal(to[0], 0);
  // Layer 13 (rank 1's alone) borders layers 12 (ranks 0, 1) and 14 (rank 1's); layer 14 borders
  // layer 15, rank 2's whole; layer 15 borders 14 (rank 1's), layer 16 borders 17 (ranks 2, 3).
  assert_int_equal(s.ghost_destinations(13, 1, to), 1);
  assert_int_equal(to[0], 0);
  assert_int_equal(s.ghost_destinations(14, 1, to), 1);
  assert_int_equal(to[0], 2);
  assert_int_equal(s.ghost_destinations(15, 2, to), 1);
  assert_int_equal(to[0], 1);
  assert_int_equal(s.ghost_destinations(16, 2, to), 1);
  assert_int_equal(to[0], 3);
  assert_int_equal(s.ghost_destinations(10, 0, to), 0);
  assert_int_equal(s.ghost_destinations(11, 0, to), 1);
  // What sph_mpi_counts reports.
  sph::DistributedCounters c;
  s.describe(1, c);
  assert_int_equal(c.axis, 2);
  assert_int_equal(c.sub_first, 12 * 16 + 6);
  assert_int_equal(c.sub_last, 15 * 16 - 1);
  assert_int_equal(c.slab_first, 12);
  assert_int_equal(c.slab_last, 14);
  s.describe(0, c);
  assert_int_equal(c.sub_first, INT32_MIN);
  assert_int_equal(c.slab_first, INT32_MIN);
  assert_int_equal(c.sub_last, 12 * 16 + 5);
  assert_int_equal(c.slab_last, 12);
  s.describe(3, c);
  assert_int_equal(c.slab_first, 17);
  assert_int_equal(c.sub_last, INT32_MAX);
  assert_int_equal(c.slab_last, INT32_MAX);
}

// Two layers of 5 over 4 ranks: targets 3, 5, 8. Sub-layer cuts 5, 9 and 17 would leave rank 1
// a slab 4 sub-layers wide (a particle then could need three ranks' ghosts), so every cut is a
// whole layer, after its crossing layer: 16, 16, and past the last layer INT32_MAX (rank 1 owns
// nothing, rank 3 nothing yet), as before sub-layers.
void test_whole_layers_when_thin(void**) {
  SlabDecomposition s(4);
  std::vector<int64_t> sixteenths(3 * 16, 0);
  for (size_t cut : {0, 1})
    for (int j : {0, 2, 4, 6, 8}) ++sixteenths[cut * 16 + static_cast<size_t>(j)];
  sixteenths[2 * 16 + 0] = 5;
  s.rebalance(0, 0, {5, 5}, sixteenths);
  const std::vector<int32_t> want{16, 16, INT32_MAX};
  assert_true(s.cuts() == want);
  assert_true(SlabDecomposition::valid(4, 0, s.cuts()));
  assert_int_equal(s.owner(15), 0);
  assert_int_equal(s.owner(16), 2);  // rank 1 owns [16, 16): nothing
  int to[2];
  assert_int_equal(s.ghost_destinations(0, 0, to), 1);  // layer 1 is rank 2's
  assert_int_equal(to[0], 2);
  sph::DistributedCounters c;
  s.describe(1, c);
  assert_true(c.sub_first > c.sub_last && c.slab_first > c.slab_last);
}

// A cut moves to its layer's end only where the slabs beside it stay allowed. Layer 0 holds 10
// particles in sixteenth 0, layer 1 holds one in each of sixteenths 0-9 and ten in sixteenth 15;
// 3 ranks, targets 10 and 20: cut 1 after sixteenth 0 of layer 0 (its rest is empty: the layer's
// end, 16, splits the same), cut 2 at 16 + 10. At 16 the middle slab [16, 26) would be 10 wide
// and not whole layers, so cut 1 stays at 1 (a 25-wide middle slab) and the ranks hold 10 each;
// moving it anyway would have thrown the decomposition back to whole layers (10 / 20 / 0).
void test_layer_end_only_where_allowed(void**) {
  SlabDecomposition s(3);
  std::vector<int64_t> sixteenths(2 * 16, 0);
  sixteenths[0] = 10;
  for (size_t j = 0; j < 10; ++j) sixteenths[16 + j] = 1;
  sixteenths[16 + 15] = 10;
  s.rebalance(0, 0, {10, 20}, sixteenths);
  assert_true(s.cuts() == (std::vector<int32_t>{1, 26}));
}

void test_valid(void**) {
  assert_true(SlabDecomposition::valid(3, 0, {5, 29}));     // a middle slab of 24
  assert_false(SlabDecomposition::valid(3, 0, {5, 28}));    // of 23
  assert_true(SlabDecomposition::valid(3, 0, {16, 32}));    // of one whole layer
  assert_true(SlabDecomposition::valid(3, 0, {-32, -16}));  // (negative layers too)
  assert_false(SlabDecomposition::valid(3, 0, {16, 33}));   // neither
  assert_true(SlabDecomposition::valid(4, 1, {7, 7, 7}));   // empty middle slabs; the outer ones free
  assert_false(SlabDecomposition::valid(3, 0, {9, 7}));     // descending
  assert_false(SlabDecomposition::valid(3, 3, {0, 48}));    // axis
  assert_false(SlabDecomposition::valid(3, 0, {0}));        // count
  assert_true(SlabDecomposition::valid(2, 0, {3}));
}

void test_imbalance(void**) {
  // Mean 10: 11 is 10 % above it, 13 is 30 %.
  assert_false(SlabDecomposition::imbalanced({9, 10, 11}, 0.2));
  assert_true(SlabDecomposition::imbalanced({7, 10, 13}, 0.2));
  assert_false(SlabDecomposition::imbalanced({0, 0}, 0.2));
}

// The definition: the non-empty ranks other than self whose sub-layers meet layers
// layer - 1 .. layer + 1, ascending.
std::vector<int> brute_destinations(const std::vector<int32_t>& cuts, int32_t layer, int self) {
  const int ranks = static_cast<int>(cuts.size()) + 1;
  const int64_t lo = (int64_t{layer} - 1) * 16, hi = (int64_t{layer} + 2) * 16 - 1;
  std::vector<int> want;
  for (int r = 0; r < ranks; ++r) {
    const int64_t b = r == 0 ? int64_t{INT32_MIN} : cuts[static_cast<size_t>(r - 1)];
    const int64_t e = r == ranks - 1 ? int64_t{INT32_MAX} : cuts[static_cast<size_t>(r)];
    // (Sub-layers are clamped to [INT32_MIN, INT32_MAX - 1]: the far layers' particles all sit
    // at its ends.)
    const int64_t clo = std::min<int64_t>(std::max<int64_t>(lo, INT32_MIN), INT32_MAX - 1);
    const int64_t chi = std::min<int64_t>(std::max<int64_t>(hi, INT32_MIN), INT32_MAX - 1);
    if (r != self && b < e && b <= chi && e > clo) want.push_back(r);
  }
  return want;
}

// The rules as the device runs them (slab_owner's binary search, the destinations' walk over
// the ranks between the window's owners) against their definitions by brute force: the owner
// is the number of cuts at or below the sub-layer; random valid decompositions (mixtures of
// whole-layer cuts, sub-layer cuts and repeats), 1 to 7 ranks, every layer around the cuts and
// at the clamped ends. For every valid decomposition no layer's window meets more than three
// slabs, so a particle, whose owner is one of them, has at most two destinations.
void test_rules_brute_force(void**) {
  std::mt19937 rng(12345);
  int tried = 0;
  for (int trial = 0; trial < 20000 && tried < 3000; ++trial) {
    const int ranks = 1 + static_cast<int>(rng() % 7);
    std::vector<int32_t> cuts(static_cast<size_t>(ranks - 1));
    for (int32_t& c : cuts) {
      const int kind = static_cast<int>(rng() % 3);
      c = kind == 0 ? 16 * (static_cast<int32_t>(rng() % 12) - 6) : static_cast<int32_t>(rng() % 200) - 100;
    }
    if (!cuts.empty() && rng() % 6 == 0) cuts.back() = INT32_MAX;
    std::sort(cuts.begin(), cuts.end());
    if (!SlabDecomposition::valid(ranks, 0, cuts)) continue;
    ++tried;
    const int count = static_cast<int>(cuts.size());
    for (int32_t sub : {INT32_MIN, INT32_MIN + 1, -101, -100, -50, -1, 0, 1, 15, 16, 99, 100, INT32_MAX}) {
      int o = 0;
      for (int32_t c : cuts) o += c <= sub ? 1 : 0;
      assert_int_equal(sph::slab_owner(cuts.data(), count, sub), o);
    }
    std::vector<int32_t> layers{-(1 << 30), (1 << 30)};
    for (int32_t l = -9; l <= 9; ++l) layers.push_back(l);
    for (int32_t layer : layers) {
      // Every rank that meets the window (self = -1: none left out) at most three, and for each
      // of them, the owner of a particle of this layer, the others.
      const std::vector<int> meet = brute_destinations(cuts, layer, -1);
      assert_true(meet.size() <= 3);
      for (int self : meet) {
        const std::vector<int> want = brute_destinations(cuts, layer, self);
        int got[2] = {-1, -1};
        const int n = sph::slab_ghost_destinations(cuts.data(), count, layer, self, got);
        assert_int_equal(n, static_cast<int>(want.size()));
        for (int k = 0; k < n; ++k) assert_int_equal(got[k], want[static_cast<size_t>(k)]);
      }
    }
  }
  assert_true(tried >= 1000);
  // Why the rule: three slabs of 8 sub-layers inside layers -1 .. 1 would give a particle of layer
  // 0 four destinations, which the device's lists (two entries a particle) cannot hold.
  const std::vector<int32_t> thin{-8, 0, 8, 16};
  assert_false(SlabDecomposition::valid(5, 0, thin));
  assert_int_equal(brute_destinations(thin, 0, 2).size(), 4u);
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uncut),
      cmocka_unit_test(test_sub_layers),
      cmocka_unit_test(test_rebalance_cuts),
      cmocka_unit_test(test_whole_layers_when_thin),
      cmocka_unit_test(test_layer_end_only_where_allowed),
      cmocka_unit_test(test_valid),
      cmocka_unit_test(test_imbalance),
      cmocka_unit_test(test_rules_brute_force),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
