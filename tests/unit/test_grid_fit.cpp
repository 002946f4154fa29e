// SPDX-License-Identifier: MIT
// The table shape fitted to the particles' extent within a budget of slots (src/physics/grid_fit.h),
// as the CUDA backend uses it at every sort: the budget is its capacity's cube of slots
// (ceil(cbrt(capacity))^3), not the CPU's two slots a particle. The dims follow the rule worked by
// hand for a thin slab and a compact ball, stay >= 3 and within the budget for any extent, and a
// table filled and walked with a fitted shape (folded or not) finds exactly the neighbours a
// brute-force search finds: the walk is right for any dims, which is what lets the dims change
// from one sort to the next.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <vector>

#include "physics/grid_fit.h"
#include "physics/neighbor_walk.h"

namespace {

using sph::CellCoord;
using sph::GridShape;
using sph::Vec3;

constexpr float kH = 0.02f;

// The CUDA backend's slots for 240,000 particles of capacity: ceil(cbrt(240000))^3 = 63^3.
constexpr double kCubeSlots = 63.0 * 63.0 * 63.0;

void test_thin_slab_by_hand(void**) {
  // The Martin & Moyce slab of bench/solver_front at 240k: cells 0..469 x 0..234 x 0..2, spans
  // (hi - lo + 1 cells and one more a side) 472 x 237 x 5. z first: fair = floor(cbrt(250047)) =
  // 63, keeps 5; y: fair = floor(sqrt(250047 / 5)) = floor(223.62) = 223 < 237; x: fair =
  // floor(250047 / (5 * 223)) = floor(224.26) = 224 < 472. So 224 x 223 x 5 = 249,760 slots.
  const GridShape g = sph::fit_grid_shape(1.0f / kH, CellCoord{0, 0, 0}, CellCoord{469, 234, 2}, kCubeSlots);
  std::printf("slab: %d x %d x %d = %u slots (budget %.0f)\n", g.nx, g.ny, g.nz, g.cell_count, kCubeSlots);
  assert_int_equal(g.nx, 224);
  assert_int_equal(g.ny, 223);
  assert_int_equal(g.nz, 5);
  assert_int_equal(g.cell_count, 224u * 223u * 5u);
  assert_true(g.inv_cell_size == 1.0f / kH);
}

void test_compact_ball_keeps_its_span(void**) {
  // A ball 61 cells across at negative coordinates: every axis keeps its span, 61 + 2 = 63, well
  // within a 100^3 budget (1M of capacity): no slot holds two cells.
  const GridShape g = sph::fit_grid_shape(1.0f / kH, CellCoord{-80, -30, -61}, CellCoord{-20, 30, -1}, 1e6);
  assert_int_equal(g.nx, 63);
  assert_int_equal(g.ny, 63);
  assert_int_equal(g.nz, 63);
}

void test_any_extent_within_the_budget(void**) {
  // From one cell to the clamp's 2^31 cells, budgets from 27 to 2^30: dims >= 3, product within
  // max(budget, 27), no axis more than its span.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int32_t> coord(-(1 << 30), 1 << 30);
  std::uniform_real_distribution<double> log_budget(std::log(27.0), std::log(1073741824.0));
  for (int k = 0; k < 20000; ++k) {
    int32_t a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = coord(rng);
      const int64_t wide =
          static_cast<int64_t>(a[i]) + std::abs(static_cast<int64_t>(coord(rng)) >> (k % 31));
      b[i] = k % 3 == 0 ? a[i] : static_cast<int32_t>(std::min<int64_t>(wide, 1 << 30));
    }
    const double budget = std::floor(std::exp(log_budget(rng)));
    const GridShape g =
        sph::fit_grid_shape(1.0f / kH, CellCoord{a[0], a[1], a[2]}, CellCoord{b[0], b[1], b[2]}, budget);
    const int32_t dims[3] = {g.nx, g.ny, g.nz};
    for (int i = 0; i < 3; ++i) {
      assert_true(dims[i] >= 3);
      assert_true(static_cast<double>(dims[i]) <= std::max(3.0, static_cast<double>(b[i]) - a[i] + 3.0));
    }
    assert_true(static_cast<double>(g.cell_count) <= std::max(budget, 27.0));
    assert_int_equal(g.cell_count, static_cast<uint32_t>(dims[0]) * dims[1] * dims[2]);
  }
}

// Points in [lo, hi), their table for `shape` (keys, a stable sort, the dense cell starts), and
// every point's neighbours by the shared walk against brute force.
size_t walk_mismatches(const GridShape& shape, const std::vector<Vec3>& points) {
  const uint32_t n = static_cast<uint32_t>(points.size());
  std::vector<uint32_t> keys(n), order(n);
  for (uint32_t i = 0; i < n; ++i) keys[i] = sph::cell_hash_of_position(shape, points[i]);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return keys[x] < keys[y]; });
  std::vector<Vec3> sorted(n);
  std::vector<uint32_t> sorted_keys(n);
  for (uint32_t i = 0; i < n; ++i) {
    sorted[i] = points[order[i]];
    sorted_keys[i] = keys[order[i]];
  }
  std::vector<uint32_t> start(static_cast<size_t>(shape.cell_count) + 1);
  for (uint32_t c = 0; c <= shape.cell_count; ++c)
    start[c] = static_cast<uint32_t>(std::lower_bound(sorted_keys.begin(), sorted_keys.end(), c) -
                                     sorted_keys.begin());
  const sph::GridView view{shape, start.data()};
  const float h2 = kH * kH;
  size_t mismatches = 0;
  std::vector<uint32_t> walked, brute;
  for (uint32_t i = 0; i < n; ++i) {
    walked.clear();
    brute.clear();
    sph::for_each_neighbor_candidate(view, sorted[i], [&](uint32_t j) {
      if (j != i && sph::length_squared(sorted[i] - sorted[j]) < h2) walked.push_back(j);
    });
    for (uint32_t j = 0; j < n; ++j)
      if (j != i && sph::length_squared(sorted[i] - sorted[j]) < h2) brute.push_back(j);
    std::sort(walked.begin(), walked.end());
    if (walked != brute) ++mismatches;
  }
  return mismatches;
}

void test_walks_exact_with_fitted_dims(void**) {
  // A thin slab of 6,000 points 2 m x 0.5 m x 3 cells (102 x 28 x 5 cells with the margins):
  // fitted within 8,000 slots (x folds onto 57 slots), within a roomy budget (nothing folds), and
  // the 20^3 cube of the same slots (x folds 5 times, y 1.4 times).
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> x(0.0f, 2.0f), y(-0.25f, 0.25f), z(0.0f, 2.5f * kH);
  std::vector<Vec3> points(6000);
  for (Vec3& p : points) p = Vec3{x(rng), y(rng), z(rng)};
  CellCoord lo{1 << 30, 1 << 30, 1 << 30}, hi{-(1 << 30), -(1 << 30), -(1 << 30)};
  for (const Vec3& p : points) {
    const CellCoord c = sph::cell_of(GridShape{1.0f / kH, 3, 3, 3, 27}, p);
    lo = CellCoord{std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = CellCoord{std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  const GridShape folded = sph::fit_grid_shape(1.0f / kH, lo, hi, 8000.0);
  const GridShape roomy = sph::fit_grid_shape(1.0f / kH, lo, hi, 1e7);
  const GridShape cube{1.0f / kH, 20, 20, 20, 8000};
  std::printf("slab of %zu points, cells (%d..%d, %d..%d, %d..%d): folded %dx%dx%d, roomy %dx%dx%d\n",
              points.size(), lo.x, hi.x, lo.y, hi.y, lo.z, hi.z, folded.nx, folded.ny, folded.nz, roomy.nx,
              roomy.ny, roomy.nz);
  assert_true(folded.nx < hi.x - lo.x + 3);  // the small budget does fold x
  assert_int_equal(roomy.nx, hi.x - lo.x + 3);
  assert_int_equal(walk_mismatches(folded, points), 0);
  assert_int_equal(walk_mismatches(roomy, points), 0);
  assert_int_equal(walk_mismatches(cube, points), 0);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_thin_slab_by_hand),
      cmocka_unit_test(test_compact_ball_keeps_its_span),
      cmocka_unit_test(test_any_extent_within_the_budget),
      cmocka_unit_test(test_walks_exact_with_fitted_dims),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
