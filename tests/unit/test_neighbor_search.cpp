// SPDX-License-Identifier: MIT
// The CPU neighbour grid (src/cpu/cpu_neighbor_grid.h) walked by the shared 27-cell search
// (src/physics/neighbor_walk.h) finds, for every particle, exactly the particles a brute-force
// O(n^2) search finds within the kernel radius: around the origin, at negative coordinates,
// 10 km away, and in clouds of blobs far apart, where the table (sized by the particles' count
// and extent at every build) is narrower than the cloud and distant cells share table slots.
// The table never has many more slots than particles, whatever their extent, and a build that
// finds more particles in one slot than the grid's cap is refused. The sort gives the same order
// on any number of workers.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/grid_layout.h"
#include "core/status.h"
#include "cpu/cpu_neighbor_grid.h"
#include "physics/neighbor_walk.h"

namespace {

using sph::Float4;
using sph::Vec3;

constexpr float kH = 0.036f;  // 1.8 x the default 2 cm spacing

struct Cloud {
  const char* name;
  Vec3 center;
  float half_extent;  // points uniform in center +- half_extent per axis
  uint32_t count;
  uint32_t blobs = 1;  // >1: that many copies of the cloud, `blob_step` apart along each axis
  float blob_step = 0.0f;
};

std::vector<Vec3> random_points(const Cloud& cloud, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> points(cloud.count);
  uint32_t k = 0;
  for (Vec3& p : points) {
    const float offset = cloud.blob_step * static_cast<float>(k++ % cloud.blobs);
    p = Vec3{static_cast<float>(cloud.center.x + offset + cloud.half_extent * u(rng)),
             static_cast<float>(cloud.center.y - offset + cloud.half_extent * u(rng)),
             static_cast<float>(cloud.center.z + 0.5f * offset + cloud.half_extent * u(rng))};
  }
  return points;
}

// The distance test of the solver (density.h, forces.h): float r^2 < float h^2.
bool within(Vec3 a, Vec3 b, float h2) { return sph::length_squared(a - b) < h2; }

struct SearchResult {
  size_t pairs = 0;        // neighbour pairs found (ordered, self excluded)
  size_t mismatches = 0;   // particles whose grid set differs from brute force
  size_t duplicates = 0;   // candidates visited twice for one query
  size_t wrapped_far = 0;  // candidates beyond the 3x3x3 block (> 2 sqrt 3 h): from a folded slot
};

SearchResult search_and_compare(const std::vector<Vec3>& points, float h,
                                sph::GridShape* shape_out = nullptr) {
  const uint32_t n = static_cast<uint32_t>(points.size());
  sph::CpuNeighborGrid grid(h, UINT32_MAX);
  std::vector<Float4> records(n);
  for (uint32_t i = 0; i < n; ++i) records[i] = sph::make_float4_record(points[i], static_cast<float>(i));
  grid.build(records.data(), n, 2);
  const sph::GridShape shape = grid.shape();
  if (shape_out) *shape_out = shape;
  // At most two slots per particle (64 for a handful), whatever the particles' extent.
  assert_true(shape.cell_count <= std::max<uint32_t>(2u * n, 64u));
  assert_true(shape.nx >= 3 && shape.ny >= 3 && shape.nz >= 3);

  // order() is a permutation; the sort is by cell hash and stable (original order within a cell).
  const auto& order = grid.order();
  assert_int_equal(order.size(), n);
  std::vector<uint32_t> seen(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    assert_true(order[i] < n);
    assert_int_equal(seen[order[i]]++, 0);
  }
  std::vector<Float4> sorted(n);
  for (uint32_t i = 0; i < n; ++i) sorted[i] = records[order[i]];
  const sph::GridView view = grid.view();
  assert_int_equal(view.cell_start[0], 0);
  assert_int_equal(view.cell_start[shape.cell_count], n);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t cell = sph::cell_hash_of_position(shape, sph::xyz(sorted[i]));
    assert_true(cell < shape.cell_count);
    assert_true(view.cell_start[cell] <= i && i < view.cell_start[cell + 1]);
    if (i > 0 && sph::cell_hash_of_position(shape, sph::xyz(sorted[i - 1])) == cell)
      assert_true(order[i - 1] < order[i]);
  }

  const float h2 = h * h;
  SearchResult result;
  std::vector<uint32_t> from_grid, brute, visits(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 xi = sph::xyz(sorted[i]);
    from_grid.clear();
    brute.clear();
    std::vector<uint32_t> visited;
    sph::for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
      if (visits[j]++ != 0) ++result.duplicates;
      visited.push_back(j);
      if (j != i && within(xi, sph::xyz(sorted[j]), h2)) from_grid.push_back(j);
      if (!within(xi, sph::xyz(sorted[j]), 12.25f * h2)) ++result.wrapped_far;
    });
    for (uint32_t j : visited) visits[j] = 0;
    for (uint32_t j = 0; j < n; ++j)
      if (j != i && within(xi, sph::xyz(sorted[j]), h2)) brute.push_back(j);
    std::sort(from_grid.begin(), from_grid.end());
    if (from_grid != brute) {
      if (result.mismatches < 5)
        std::printf("  particle at (%.9g, %.9g, %.9g): grid finds %zu neighbours, brute force %zu\n", xi.x,
                    xi.y, xi.z, from_grid.size(), brute.size());
      ++result.mismatches;
    }
    result.pairs += brute.size();
  }
  return result;
}

// wraps: whether the cloud is wider than the table, so distant cells share slots.
void run_cloud(const Cloud& cloud, uint32_t seed, bool wraps) {
  sph::GridShape shape{};
  const SearchResult r = search_and_compare(random_points(cloud, seed), kH, &shape);
  const double cells_across = (2.0 * cloud.half_extent + cloud.blob_step * (cloud.blobs - 1)) / kH;
  std::printf(
      "%s: %u points, table %dx%dx%d, cloud %.0f cells across, %.1f neighbours per point, "
      "%zu far candidates from wrapped slots, %zu mismatches\n",
      cloud.name, cloud.count, shape.nx, shape.ny, shape.nz, cells_across,
      static_cast<double>(r.pairs) / cloud.count, r.wrapped_far, r.mismatches);
  assert_int_equal(r.duplicates, 0);  // the 27 cells are 27 distinct table slots
  assert_int_equal(r.mismatches, 0);
  if (wraps)
    assert_true(r.wrapped_far > 0);  // the case really exercises folded slots
  else
    assert_int_equal(r.wrapped_far, 0);
  assert_true(r.pairs > cloud.count);  // the clouds are dense enough to have neighbours
}

void test_cloud_at_origin(void**) {
  // Straddles 0, where floor() of negative coordinates matters; fits the table (no wrap).
  run_cloud(Cloud{"origin", Vec3{0.0f, 0.0f, 0.0f}, 0.2f, 2000}, 1, false);
}

void test_cloud_negative(void**) {
  run_cloud(Cloud{"negative", Vec3{-3.3f, -7.1f, -0.5f}, 0.2f, 2000}, 2, false);
}

void test_cloud_far_away(void**) {
  // 10 km out, float positions are spaced ~1 mm: still far finer than h.
  run_cloud(Cloud{"far +1e4", Vec3{1e4f, 1e4f, 1e4f}, 0.2f, 2000}, 3, false);
  run_cloud(Cloud{"far mixed", Vec3{-1e4f, 1e4f, -1e4f}, 0.2f, 2000}, 4, false);
}

void test_cloud_wraps_table(void**) {
  // Blobs metres apart: the particles span thousands of cells per axis, the table has about
  // one slot per particle, so the blobs fold onto each other and slots hold distant cells.
  run_cloud(Cloud{"wrap 3 blobs", Vec3{0.0f, 0.0f, 0.0f}, 0.1f, 3000, 3, 5.0f}, 5, true);
  run_cloud(Cloud{"wrap 7 blobs", Vec3{-20.0f, 5.0f, -3.0f}, 0.08f, 3000, 7, 1.3f}, 6, true);
  run_cloud(Cloud{"wrap far", Vec3{-1e4f, 1e4f, 5e3f}, 0.1f, 3000, 4, 40.0f}, 7, true);
}

void test_dense_cluster(void**) {
  // Hundreds of particles per cell.
  run_cloud(Cloud{"dense", Vec3{0.01f, 0.01f, 0.01f}, 0.03f, 1500}, 8, false);
}

// Points on and within a few float steps of cell boundaries (multiples of h), where the
// rounding of x / h decides the cell.
void test_points_on_cell_boundaries(void**) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> cell(-6, 6), nudge(-3, 3), axis(0, 2);
  std::uniform_real_distribution<float> u(-6.0f * kH, 6.0f * kH);
  std::vector<Vec3> points(2000);
  for (Vec3& p : points) {
    float c[3] = {u(rng), u(rng), u(rng)};
    // Put one or two coordinates on a boundary, moved by up to 3 float steps.
    for (int k = 0, m = 1 + (axis(rng) > 0); k < m; ++k) {
      float& v = c[axis(rng)];
      v = static_cast<float>(cell(rng)) * kH;
      for (int s = nudge(rng); s != 0; s += (s > 0 ? -1 : 1)) v = std::nextafter(v, s > 0 ? 1e9f : -1e9f);
    }
    p = Vec3{c[0], c[1], c[2]};
  }
  const SearchResult r = search_and_compare(points, kH);
  std::printf("cell boundaries: %.1f neighbours per point, %zu mismatches\n",
              static_cast<double>(r.pairs) / points.size(), r.mismatches);
  assert_int_equal(r.duplicates, 0);
  assert_int_equal(r.mismatches, 0);
  assert_true(r.pairs > points.size());
}

// Pairs closer than h that straddle two cell boundaries: a just below the boundary k h (in
// cell k - 1), b just under h further (near the boundary (k + 1) h). Whether b lands in
// cell k or k + 1 depends on the rounding of b / h (and of 1 / h, which may exceed the exact
// value); if it lands in k + 1, the pair is two cells apart and the 27-cell walk misses it.
size_t straddle_pairs(double base, float h, size_t* mismatches) {
  size_t cases = 0;
  for (int k = -20; k <= 20; ++k)
    for (int below = 0; below <= 4; ++below)
      for (int shorter = 1; shorter <= 6; ++shorter) {
        float a = static_cast<float>(base + k * static_cast<double>(h));
        for (int s = 0; s < below; ++s) a = std::nextafter(a, -1e30f);
        float b = a + h;
        for (int s = 0; s < shorter; ++s) b = std::nextafter(b, -1e30f);
        const std::vector<Vec3> pair = {Vec3{a, 0.25f * h, 0.25f * h}, Vec3{b, 0.25f * h, 0.25f * h}};
        if (!within(pair[0], pair[1], h * h)) continue;
        ++cases;
        *mismatches += search_and_compare(pair, h).mismatches;
      }
  return cases;
}

void test_pairs_straddling_boundaries(void**) {
  // Several kernel radii: whether float(1 / h) rounds up or down differs between them.
  const float radii[] = {0.036f, 0.1f, 0.05f, 0.07f, 0.3f, 0.0125f, 0.9f, 1.0f / 3.0f, 0.045f, 0.018f};
  for (float h : radii)
    for (double base : {0.0, -1e3, 1e4}) {
      size_t mismatches = 0;
      const size_t cases = straddle_pairs(base, h, &mismatches);
      if (mismatches != 0)
        std::printf("h = %g around %g: %zu particles of %zu straddling pairs miss their neighbour\n", h, base,
                    mismatches, 2 * cases);
      assert_true(cases > 100);
      assert_int_equal(mismatches, 0);
    }
}

// 100 particles a kilometre apart along each axis (the case of a world of capacity 2^30 with
// 100 particles, issue 23 item 9): the table has at most 200 slots, where the capacity-sized
// table had 2^30 (4 GiB). A long thin column keeps its length.
void test_table_follows_the_particles(void**) {
  std::vector<Vec3> sparse(100);
  for (uint32_t i = 0; i < 100; ++i)
    sparse[i] = Vec3{1000.0f * static_cast<float>(i % 5), -1000.0f * static_cast<float>(i / 20), 7.0f * i};
  sph::GridShape shape{};
  search_and_compare(sparse, kH, &shape);
  std::printf("sparse: 100 points, table %dx%dx%d = %u slots\n", shape.nx, shape.ny, shape.nz,
              shape.cell_count);
  assert_true(shape.cell_count <= 200u);
  std::vector<Vec3> column(3000);
  for (uint32_t i = 0; i < 3000; ++i)
    column[i] = Vec3{0.001f * (i % 3), 0.5f * kH * static_cast<float>(i), 0.0f};
  const SearchResult r = search_and_compare(column, kH, &shape);
  std::printf("column: 3000 points, table %dx%dx%d\n", shape.nx, shape.ny, shape.nz);
  assert_int_equal(shape.nx, 3);
  assert_int_equal(shape.nz, 3);
  assert_true(shape.ny >= 600);  // 1500 cells tall: folded at most 2.5 times
  assert_int_equal(r.mismatches, 0);
}

// More particles in one cell than the grid's cap: the build is refused (Error(Capacity), which
// the world turns into a failed, rolled-back step), and exactly the cap is accepted.
void test_crowded_cell_is_refused(void**) {
  std::vector<Float4> records(201, sph::make_float4_record(Vec3{0.5f, 0.5f, 0.5f}, 0.0f));
  sph::CpuNeighborGrid grid(kH, 200);
  bool refused = false;
  try {
    grid.build(records.data(), 201, 1);
  } catch (const sph::Error& e) {
    refused = e.status() == sph::Status::Capacity;
    std::printf("refused: %s\n", e.what());
  }
  assert_true(refused);
  grid.build(records.data(), 200, 1);
  assert_int_equal(grid.view().cell_start[grid.shape().cell_count], 200);
  // The default cap: 64 times the particles of a cell of fluid at rest (sqrt(2) (h/s)^3).
  assert_int_equal(sph::max_particles_per_cell(0.02f, 0.036f), 528u);
}

// The sort's order and cell-start table are exactly those of a stable sort by cell hash
// (std::stable_sort), on 1, 2, 3, 4 and 7 workers, for a cloud above the parallel minimum that
// wraps the table. A crowded cell is refused on 2 workers as on one, with the same slot named.
void test_sort_same_on_any_workers(void**) {
  const Cloud cloud{"wide", Vec3{0.1f, -0.2f, 0.3f}, 40.0f * kH, 20000, 3, 30.0f * kH};
  const std::vector<Vec3> points = random_points(cloud, 11u);
  const uint32_t n = cloud.count;
  std::vector<Float4> records(n);
  for (uint32_t i = 0; i < n; ++i) records[i] = sph::make_float4_record(points[i], 0.0f);
  for (unsigned workers : {1u, 2u, 3u, 4u, 7u}) {
    sph::CpuNeighborGrid grid(kH, UINT32_MAX);
    grid.build(records.data(), n, workers);
    const sph::GridShape shape = grid.shape();
    std::vector<uint32_t> expected(n);
    for (uint32_t i = 0; i < n; ++i) expected[i] = i;
    std::stable_sort(expected.begin(), expected.end(), [&](uint32_t a, uint32_t b) {
      return sph::cell_hash_of_position(shape, points[a]) < sph::cell_hash_of_position(shape, points[b]);
    });
    assert_true(std::equal(grid.order().begin(), grid.order().end(), expected.begin(), expected.end()));
    std::vector<uint32_t> starts(shape.cell_count + 1, 0u);
    for (uint32_t i = 0; i < n; ++i) ++starts[sph::cell_hash_of_position(shape, points[i]) + 1];
    for (uint32_t c = 0; c < shape.cell_count; ++c) starts[c + 1] += starts[c];
    for (uint32_t c = 0; c <= shape.cell_count; ++c) assert_int_equal(grid.view().cell_start[c], starts[c]);
  }
  // Two crowded cells, at the two ends of the particles: the lower slot is named.
  std::vector<Float4> crowded(records);
  for (uint32_t i = 0; i < 300; ++i) {
    crowded[i] = sph::make_float4_record(Vec3{0.5f, 0.5f, 0.5f}, 0.0f);
    crowded[n - 1 - i] = sph::make_float4_record(Vec3{-0.5f, 0.5f, 0.5f}, 0.0f);
  }
  std::string messages[2];
  for (unsigned workers : {1u, 2u}) {
    sph::CpuNeighborGrid grid(kH, 200);
    try {
      grid.build(crowded.data(), n, workers);
    } catch (const sph::Error& e) {
      assert_int_equal(static_cast<int>(e.status()), static_cast<int>(sph::Status::Capacity));
      messages[workers - 1] = e.what();
    }
  }
  std::printf("crowded on 2 workers: %s\n", messages[1].c_str());
  assert_false(messages[0].empty());
  assert_true(messages[0] == messages[1]);
}

}  // namespace

int main() {
  const CMUnitTest tests[] = {
      cmocka_unit_test(test_cloud_at_origin),
      cmocka_unit_test(test_cloud_negative),
      cmocka_unit_test(test_cloud_far_away),
      cmocka_unit_test(test_cloud_wraps_table),
      cmocka_unit_test(test_dense_cluster),
      cmocka_unit_test(test_points_on_cell_boundaries),
      cmocka_unit_test(test_pairs_straddling_boundaries),
      cmocka_unit_test(test_table_follows_the_particles),
      cmocka_unit_test(test_crowded_cell_is_refused),
      cmocka_unit_test(test_sort_same_on_any_workers),
  };
  return cmocka_run_group_tests_name("neighbor_search", tests, nullptr, nullptr);
}
