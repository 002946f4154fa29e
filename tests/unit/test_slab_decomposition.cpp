// SPDX-License-Identifier: MIT
// A distributed world's slabs (src/core/slab_decomposition.h): who owns a cell layer, who needs
// it as a ghost, when the ranks are out of balance, and where a rebalance cuts. Every expected
// value is worked out by hand from the histogram.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <vector>

#include "core/slab_decomposition.h"

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

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uncut),
      cmocka_unit_test(test_rebalance_cuts),
      cmocka_unit_test(test_more_ranks_than_layers),
      cmocka_unit_test(test_imbalance),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
