// SPDX-License-Identifier: MIT
// The CPU's partial update of a boundary map after its SDF changed in part (src/cpu/cpu_boundary_maps.h,
// changed_voxels and update_boundary_map; CpuBoundaryMaps::bind from an asset's second change on).
// What must hold, on an open tank (a container's level above zero), a solid box (below zero) and a
// scaled, rippled ball on a rotated, sheared grid of unequal voxels (the reach along each index
// axis is not the same):
//   - changed_voxels finds exactly the bounding box of the voxels whose distance changed;
//   - the update gives the map a whole recomputation gives, bit for bit (every channel of every
//     voxel), for a dent inside the grid and one against its faces, with the slope bound the cache
//     uses (the old cells' maxima and the changed box's cells', at least the whole grid's bound);
//   - the claim it rests on, checked directly against two whole computations: every voxel outside
//     the box the update recomputed keeps its correction, and outside that box grown by one its
//     slopes; and the update's reach is needed: some voxels outside the changed box but inside the
//     recomputed one do change (so a reach of zero would fail the comparison above);
//   - the cache: a change's recorded box recomputes its reach (the asset's first change too), a
//     velocity-only change nothing, a change of unknown extent the whole map, after which the map
//     keeps its distances and narrows a whole-grid change to what moved; the map is always the
//     whole computation's; and the asset's record of its changes.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/sdf_asset.h"
#include "core/sdf_shapes.h"
#include "cpu/cpu_boundary_maps.h"
#include "physics/boundary_map.h"
#include "rippled_ball.h"

namespace {

const float kH = 0.0255f;  // the loads' tests' kernel radius (1 cm lattice step)
const sph::CpuParallel kWorkers(2);

std::shared_ptr<sph::SdfAsset> tank() {
  sph::ShapeSpec s;
  s.kind = sph::ShapeKind::Box;
  s.half_extents = sph::Vec3{0.08f, 0.06f, 0.07f};
  s.wall_thickness = 0.02f;
  s.open_top = true;
  s.voxel_size = 0.006f;
  return sph::build_shape_sdf(s, 1u << 22);
}

std::shared_ptr<sph::SdfAsset> solid_box() {
  sph::ShapeSpec s;
  s.kind = sph::ShapeKind::Box;
  s.half_extents = sph::Vec3{0.07f, 0.05f, 0.06f};
  s.voxel_size = 0.0055f;
  return sph::build_shape_sdf(s, 1u << 22);
}

size_t voxel_index(const sph::SdfAsset& a, int32_t i, int32_t j, int32_t k) {
  return static_cast<size_t>(i) + static_cast<size_t>(a.nx()) * (j + static_cast<size_t>(a.ny()) * k);
}

bool inside(const sph::VoxelBox& b, int32_t i, int32_t j, int32_t k) {
  return i >= b.lo[0] && i < b.hi[0] && j >= b.lo[1] && j < b.hi[1] && k >= b.lo[2] && k < b.hi[2];
}

// Carves a ball of radius `radius` (local units) about voxel `centre` out of the solid (the SDF's
// max with the ball's outside distance) and adds a small ripple where it changes anything; returns
// the bounding box of the voxels it changed, found voxel by voxel.
sph::VoxelBox dent(sph::SdfAsset& a, const int32_t centre[3], float radius) {
  const sph::Vec3 c = sph::apply_affine(
      a.index_to_local(),
      sph::Vec3{static_cast<float>(centre[0]), static_cast<float>(centre[1]), static_cast<float>(centre[2])});
  sph::VoxelBox box;
  bool any = false;
  for (int32_t k = 0; k < a.nz(); ++k)
    for (int32_t j = 0; j < a.ny(); ++j)
      for (int32_t i = 0; i < a.nx(); ++i) {
        const sph::Vec3 p =
            sph::apply_affine(a.index_to_local(),
                              sph::Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)});
        const float out = radius - sph::length(p - c);
        if (!(out > -0.5f * radius)) continue;
        float& d = a.distance()[voxel_index(a, i, j, k)];
        const float before = d;
        d = std::fmax(d, out) + 0.0003f * std::sin(900.0f * p.y);
        if (std::memcmp(&d, &before, sizeof d) == 0) continue;
        if (!any) {
          box.lo[0] = i, box.lo[1] = j, box.lo[2] = k;
          box.hi[0] = i + 1, box.hi[1] = j + 1, box.hi[2] = k + 1;
          any = true;
        }
        const int32_t at[3] = {i, j, k};
        for (int ax = 0; ax < 3; ++ax)
          box.lo[ax] = std::min(box.lo[ax], at[ax]), box.hi[ax] = std::max(box.hi[ax], at[ax] + 1);
      }
  assert_true(any);
  return box;
}

// One dent on `asset` at `level`: the update against two whole computations.
void check_dent(sph::SdfAsset& asset, float level, const int32_t centre[3], float radius, const char* name) {
  const sph::HostVector<sph::Float4> before = sph::compute_boundary_map(asset, kH, level, kWorkers);
  const sph::HostVector<float> distances = asset.distance();
  sph::SdfSlopeMaxima maxima = sph::sdf_slope_maxima(asset, asset.whole_grid(), kWorkers);
  const sph::VoxelBox expected = dent(asset, centre, radius);
  const sph::VoxelBox changed = sph::changed_voxels(asset, distances, asset.whole_grid(), kWorkers);
  for (int a = 0; a < 3; ++a) {
    assert_int_equal(changed.lo[a], expected.lo[a]);
    assert_int_equal(changed.hi[a], expected.hi[a]);
  }
  // The bound the cache uses: the old cells' maxima and the changed box's cells' (at least the
  // whole grid's now).
  maxima.add(sph::sdf_slope_maxima(asset, changed, kWorkers));
  const sph::SdfSlope slope = sph::sdf_slope_from(asset, maxima);
  assert_true(slope.bound >= sph::sdf_slope(asset, kWorkers).bound);
  sph::HostVector<sph::Float4> updated = before;
  const sph::VoxelBox recomputed =
      sph::update_boundary_map(asset, kH, level, kWorkers, changed, slope, updated);
  const sph::HostVector<sph::Float4> after = sph::compute_boundary_map(asset, kH, level, kWorkers);
  size_t differing = 0, kept_wrongly = 0, moved_outside = 0, reached = 0;
  for (int32_t k = 0; k < asset.nz(); ++k)
    for (int32_t j = 0; j < asset.ny(); ++j)
      for (int32_t i = 0; i < asset.nx(); ++i) {
        const size_t v = voxel_index(asset, i, j, k);
        differing += std::memcmp(&updated[v], &after[v], sizeof(sph::Float4)) != 0;
        const bool value_moved = std::memcmp(&before[v].x, &after[v].x, sizeof(float)) != 0;
        const bool slope_moved = std::memcmp(&before[v].y, &after[v].y, 3 * sizeof(float)) != 0;
        // Outside the recomputed box nothing may move (the values), nor outside it grown by one (the slopes).
        bool near = false;
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) near = near || inside(recomputed, i + di, j + dj, k + dk);
        kept_wrongly += (value_moved && !inside(recomputed, i, j, k)) || (slope_moved && !near);
        moved_outside += value_moved && !inside(changed, i, j, k);
        reached += inside(recomputed, i, j, k);
      }
  std::printf(
      "%-24s level %+.3f: %d x %d x %d voxels, changed box %llu, recomputed %zu, values moved "
      "outside the changed box %zu, differing from a whole computation %zu\n",
      name, static_cast<double>(level), asset.nx(), asset.ny(), asset.nz(),
      static_cast<unsigned long long>(changed.voxels()), reached, moved_outside, differing);
  assert_int_equal(differing, 0);
  assert_int_equal(kept_wrongly, 0);
  assert_true(moved_outside > 0);  // the reach matters
  assert_int_equal(reached, recomputed.voxels());
}

void test_tank(void**) {
  const auto asset = tank();
  const int32_t floor_centre[3] = {asset->nx() / 2, 4, asset->nz() / 2};
  check_dent(*asset, 0.007f, floor_centre, 0.02f, "open tank, floor");
  // Against the grid's faces (the rays' samples there clamp to them).
  const int32_t corner[3] = {1, 1, 1};
  check_dent(*asset, 0.007f, corner, 0.025f, "open tank, grid corner");
}

void test_solid_box(void**) {
  const auto asset = solid_box();
  const int32_t face[3] = {asset->nx() / 2, asset->ny() / 2, asset->nz() - 6};
  check_dent(*asset, -0.007f, face, 0.015f, "solid box, face");
}

void test_sheared_grid(void**) {
  const int dims[3] = {40, 32, 28};
  const auto asset = rippled_ball(dims, 0.045);
  const int32_t side[3] = {asset->nx() - 8, asset->ny() / 2, asset->nz() / 2};
  check_dent(*asset, -0.01f, side, 0.02f, "rippled ball, sheared");
}

// The cache, against whole computations: a change's recorded box recomputes its reach (the first
// change too), a velocity-only change nothing, a change of unknown extent (touch) the whole map and
// from then on the map keeps its distances, so that a later whole-grid change is narrowed to what
// moved; more changes than the asset records between two steps recompute the whole map.
void test_cache(void**) {
  const auto asset = tank();
  const float level = 0.007f;
  sph::CpuBoundaryMaps maps;
  const sph::Float4* map = nullptr;
  auto frame = [&]() {
    maps.begin_frame();
    map = maps.bind(*asset, kH, level, kWorkers);
    maps.end_frame();
  };
  auto expect_whole_map = [&]() {
    const sph::HostVector<sph::Float4> whole = sph::compute_boundary_map(*asset, kH, level, kWorkers);
    assert_int_equal(std::memcmp(map, whole.data(), whole.size() * sizeof(sph::Float4)), 0);
  };
  frame();
  const uint64_t voxels = asset->voxel_count();
  assert_int_equal(maps.builds(), 1);
  assert_int_equal(maps.voxels_computed(), voxels);
  assert_int_equal(maps.bytes(), voxels * sizeof(sph::Float4));
  uint64_t computed = voxels;

  const int32_t a[3] = {asset->nx() / 2, 4, asset->nz() / 2}, b[3] = {4, asset->ny() / 2, 4};
  asset->record_change(dent(*asset, a, 0.015f));  // as sph_sdf_update records its box
  frame();
  const uint64_t first = maps.voxels_computed() - computed;
  computed += first;
  std::printf("cache: %llu voxels; a recorded dent recomputed %llu\n",
              static_cast<unsigned long long>(voxels), static_cast<unsigned long long>(first));
  assert_int_equal(maps.builds(), 1);
  assert_true(first > 0 && first < voxels / 2);
  assert_int_equal(maps.bytes(), voxels * sizeof(sph::Float4));  // no distances kept
  expect_whole_map();

  asset->record_change(sph::VoxelBox{});  // the velocity or friction channel
  frame();
  assert_int_equal(maps.voxels_computed(), computed);
  assert_int_equal(maps.builds(), 1);

  asset->touch();  // unknown extent: the whole map, and the distances kept from now on
  frame();
  computed += voxels;
  assert_int_equal(maps.voxels_computed(), computed);
  assert_int_equal(maps.builds(), 2);
  assert_int_equal(maps.bytes(), voxels * (sizeof(sph::Float4) + sizeof(float)));

  dent(*asset, b, 0.01f);
  asset->record_change(asset->whole_grid());  // the whole grid re-sent, one dent in it
  frame();
  const uint64_t narrowed = maps.voxels_computed() - computed;
  computed += narrowed;
  std::printf("cache: the whole grid re-sent with one dent recomputed %llu\n",
              static_cast<unsigned long long>(narrowed));
  assert_int_equal(maps.builds(), 2);
  assert_true(narrowed > 0 && narrowed < voxels / 2);
  expect_whole_map();

  // More changes than the asset records, each a small box, between two steps: the whole map (the
  // kept distances narrow it only when they are kept; a fresh cache here keeps none).
  sph::CpuBoundaryMaps fresh;
  fresh.begin_frame();
  fresh.bind(*asset, kH, level, kWorkers);
  fresh.end_frame();
  for (int change = 0; change < 17; ++change) {
    const int32_t at[3] = {6 + change, 6, 6};
    asset->record_change(dent(*asset, at, 0.004f));
  }
  fresh.begin_frame();
  map = fresh.bind(*asset, kH, level, kWorkers);
  fresh.end_frame();
  assert_int_equal(fresh.builds(), 2);
  expect_whole_map();

  // Another kernel radius: the whole map, and no distances kept until it changes.
  maps.begin_frame();
  maps.bind(*asset, 0.03f, level, kWorkers);
  maps.end_frame();
  assert_int_equal(maps.builds(), 3);
  assert_int_equal(maps.bytes(), voxels * sizeof(sph::Float4));
}

// The asset's record of its changes (SdfAsset::distance_changed_since).
void test_change_record(void**) {
  const auto asset = solid_box();
  const uint64_t v0 = asset->version();
  sph::VoxelBox box;
  assert_true(asset->distance_changed_since(v0, &box));
  assert_true(box.empty());
  sph::VoxelBox one, two;
  one.lo[0] = 1, one.lo[1] = 2, one.lo[2] = 3, one.hi[0] = 4, one.hi[1] = 5, one.hi[2] = 6;
  two.lo[0] = 10, two.lo[1] = 0, two.lo[2] = 4, two.hi[0] = 11, two.hi[1] = 1, two.hi[2] = 9;
  asset->record_change(one);
  asset->record_change(sph::VoxelBox{});
  asset->record_change(two);
  assert_int_equal(asset->version(), v0 + 3);
  assert_true(asset->distance_changed_since(v0, &box));
  const int32_t lo[3] = {1, 0, 3}, hi[3] = {11, 5, 9};
  for (int a = 0; a < 3; ++a) assert_true(box.lo[a] == lo[a] && box.hi[a] == hi[a]);
  assert_true(asset->distance_changed_since(v0 + 1, &box));
  for (int a = 0; a < 3; ++a) assert_true(box.lo[a] == two.lo[a] && box.hi[a] == two.hi[a]);
  for (int change = 0; change < 16; ++change) asset->record_change(sph::VoxelBox{});
  assert_false(asset->distance_changed_since(v0, &box));  // 19 changes ago: no longer all recorded
  assert_true(asset->distance_changed_since(v0 + 3, &box));
  assert_true(box.empty());
  assert_false(asset->distance_changed_since(asset->version() + 1, &box));  // a version not reached
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tank),  cmocka_unit_test(test_solid_box),     cmocka_unit_test(test_sheared_grid),
      cmocka_unit_test(test_cache), cmocka_unit_test(test_change_record),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
