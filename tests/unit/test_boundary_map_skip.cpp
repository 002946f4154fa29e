// SPDX-License-Identifier: MIT
// The boundary map's ray skip (src/physics/boundary_map.h, integrate_rays; sdf_slope in
// src/cpu/cpu_boundary_maps.h): a ray step is left unsampled when a sample's distance, over a bound
// on the SDF's slope, proves every ray of the polar angle outside the solid there. Two things must
// hold, on SDFs that are distances (a solid box, an open tank, a ball) and on one that is not (a
// scaled and rippled ball on a rotated, sheared grid of unequal voxels):
//   - sdf_slope bounds the slope of sample_distance: over random pairs of nearby points, inside
//     the grid and up to four voxels outside it, |f(a) - f(b)| <= L |a - b| (plus 1e-6 of the
//     values' scale for the float evaluation). A bound that failed would let the skip drop a solid
//     sample. Also reported: the largest slope the pairs saw against L (a distance's is 1; a bound
//     far above it would skip nothing);
//   - the map is the same, bit for bit, with the skip and without it (every voxel's correction,
//     at a solid's level below zero and a container's above), since a skipped sample could only
//     have added nothing. That the comparison sees the skip at all: with a bound 20 times too
//     small (a false proof) the same comparison finds voxels that differ.
// A grid holding a non-finite value gives no bound (every sample taken).
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
#include <random>

#include "core/sdf_asset.h"
#include "core/sdf_shapes.h"
#include "cpu/cpu_boundary_maps.h"
#include "physics/boundary_map.h"
#include "rippled_ball.h"

namespace {

const float kH = 0.0255f;  // the loads' tests' kernel radius (1 cm lattice step)

std::shared_ptr<sph::SdfAsset> shape(sph::ShapeKind kind, float voxel) {
  sph::ShapeSpec s;
  s.kind = kind;
  s.half_extents = sph::Vec3{0.03f, 0.03f, 0.03f};
  s.radius = 0.03f;
  s.voxel_size = voxel;
  if (kind == sph::ShapeKind::Box && voxel > 0.006f) s.wall_thickness = 0.02f, s.open_top = true;
  return sph::build_shape_sdf(s, 1u << 22);
}

// The bound against random pairs of nearby points; returns the largest slope seen over L.
double check_bound(const sph::SdfAsset& asset, const char* name) {
  const sph::SdfSlope slope = sph::sdf_slope(asset, sph::CpuParallel(2));
  assert_true(slope.bound > 0.0f);
  const sph::SdfGridView g = asset.host_view();
  const double voxel = asset.max_voxel_size();
  double scale = 0.0;
  for (float v : asset.distance()) scale = std::fmax(scale, std::fabs(v));
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double worst = 0.0, violation = 0.0;
  for (int pair = 0; pair < 40000; ++pair) {
    const sph::Vec3 idx{-4.0f + unit(random) * (asset.nx() + 7.0f),
                        -4.0f + unit(random) * (asset.ny() + 7.0f),
                        -4.0f + unit(random) * (asset.nz() + 7.0f)};
    const sph::Vec3 a = sph::apply_affine(asset.index_to_local(), idx);
    sph::Vec3 d{unit(random) - 0.5f, unit(random) - 0.5f, unit(random) - 0.5f};
    const float length = sph::length(d);
    if (!(length > 0.01f)) continue;
    const float apart = static_cast<float>(voxel) * 2.0f * unit(random) + 1e-4f;
    const sph::Vec3 b = a + d * (apart / length);
    const double step = sph::length(b - a);
    const double change =
        std::fabs(static_cast<double>(sph::sample_distance(g, a)) - sph::sample_distance(g, b));
    worst = std::fmax(worst, change / step);
    violation = std::fmax(violation, change - (slope.bound * step + 1e-6 * scale));
  }
  std::printf("%-28s bound %.4f, largest slope of 40000 pairs %.4f (%.2f of the bound)\n", name,
              static_cast<double>(slope.bound), worst, worst / slope.bound);
  assert_true(violation <= 0.0);
  return worst / slope.bound;
}

// Every voxel's correction with the skip and without it, bit for bit; returns the band's voxels.
size_t check_same_map(const sph::SdfAsset& asset, float level) {
  const sph::SdfSlope slope = sph::sdf_slope(asset, sph::CpuParallel(2));
  sph::SdfSlope false_proof = slope;
  false_proof.bound = slope.bound / 20.0f;
  const sph::SdfGridView g = asset.host_view();
  size_t band = 0, differing = 0, differing_false = 0;
  for (int32_t k = 0; k < asset.nz(); ++k)
    for (int32_t j = 0; j < asset.ny(); ++j)
      for (int32_t i = 0; i < asset.nx(); ++i) {
        const float with = sph::boundary_map_correction(g, asset.index_to_local(), i, j, k, kH, level, slope);
        const float without =
            sph::boundary_map_correction(g, asset.index_to_local(), i, j, k, kH, level, sph::SdfSlope{});
        const float phi =
            g.distance[i + static_cast<size_t>(asset.nx()) * (j + static_cast<size_t>(asset.ny()) * k)];
        band += std::fabs(phi - level) < kH;
        differing += std::memcmp(&with, &without, sizeof(float)) != 0;
        const float wrong =
            sph::boundary_map_correction(g, asset.index_to_local(), i, j, k, kH, level, false_proof);
        differing_false += std::memcmp(&wrong, &without, sizeof(float)) != 0;
      }
  std::printf("  level %+.4f: %zu band voxels, %zu differ (with a bound 20 times too small: %zu)\n",
              static_cast<double>(level), band, differing, differing_false);
  assert_int_equal(differing, 0);
  assert_true(differing_false > 0);
  assert_true(band > 0);
  return band;
}

void test_distances(void** state) {
  (void)state;
  const struct {
    sph::ShapeKind kind;
    float voxel;
    const char* name;
  } cases[] = {{sph::ShapeKind::Box, 0.0045f, "solid box, 4.5 mm"},
               {sph::ShapeKind::Box, 0.0065f, "open tank, 6.5 mm"},
               {sph::ShapeKind::Sphere, 0.006f, "ball, 6 mm"}};
  for (const auto& c : cases) {
    const auto asset = shape(c.kind, c.voxel);
    const double ratio = check_bound(*asset, c.name);
    // A distance's trilinear interpolant has slopes up to 1 along the surface's normal; the bound
    // is at most sqrt(3) + the extension's share times that, so at least 0.4 of it is seen.
    assert_true(ratio > 0.4);
    check_same_map(*asset, -0.007f);  // a solid: {phi < -delta}
    check_same_map(*asset, 0.007f);   // a container's calibration offset
  }
}

void test_not_a_distance(void** state) {
  (void)state;
  const int dims[3] = {24, 20, 18};
  const auto asset = rippled_ball(dims, 0.03);
  check_bound(*asset, "rippled ball, sheared grid");
  check_same_map(*asset, -0.01f);
  check_same_map(*asset, 0.01f);
}

void test_non_finite_gives_no_bound(void** state) {
  (void)state;
  const auto asset = shape(sph::ShapeKind::Sphere, 0.006f);
  asset->distance()[asset->distance().size() / 2] = INFINITY;
  const sph::SdfSlope slope = sph::sdf_slope(*asset, sph::CpuParallel(2));
  assert_true(slope.bound == 0.0f);
  const sph::RaySkip skip = sph::ray_skip_at(sph::Vec3{0.0f, 0.0f, 0.0f}, kH, 0.0f, slope);
  assert_true(skip.inverse == 0.0f);
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_distances),
      cmocka_unit_test(test_not_a_distance),
      cmocka_unit_test(test_non_finite_gives_no_bound),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
