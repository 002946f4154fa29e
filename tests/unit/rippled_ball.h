// SPDX-License-Identifier: MIT
// An SDF asset that is not a distance, on a grid that is not axis-aligned, for the boundary map's
// tests (test_boundary_map_skip, test_boundary_map_update): 2.5 times the distance of a ball of
// `radius` about the local origin plus a ripple, on a grid of `dims` rotated by 0.7 rad about
// (1, 2, 3), sheared (0.3), with voxels of 4, 5 and 6 mm, centred on the origin.
#pragma once

#include <cmath>
#include <memory>

#include "core/sdf_asset.h"

inline std::shared_ptr<sph::SdfAsset> rippled_ball(const int dims[3], double radius) {
  const double angle = 0.7, n[3] = {1.0 / std::sqrt(14.0), 2.0 / std::sqrt(14.0), 3.0 / std::sqrt(14.0)};
  const double c = std::cos(angle), s = std::sin(angle);
  double rotation[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      const double cross = r == k ? 0.0 : ((r + 1) % 3 == k ? -n[3 - r - k] : n[3 - r - k]);
      rotation[r][k] = (r == k ? c : 0.0) + (1.0 - c) * n[r] * n[k] + s * cross;
    }
  const double scale[3] = {0.004, 0.005, 0.006}, shear = 0.3;
  sph::Affine3x4 to_local{};
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      const double column = rotation[r][k] * scale[k] + (k == 1 ? shear * rotation[r][0] * scale[0] : 0.0);
      to_local.m[4 * r + k] = static_cast<float>(column);
    }
    double centre = 0.0;
    for (int k = 0; k < 3; ++k) centre += static_cast<double>(to_local.m[4 * r + k]) * 0.5 * (dims[k] - 1);
    to_local.m[4 * r + 3] = static_cast<float>(-centre);
  }
  auto asset = std::make_shared<sph::SdfAsset>(dims[0], dims[1], dims[2], to_local);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        const sph::Vec3 p = sph::apply_affine(
            to_local, sph::Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)});
        const double r = std::sqrt(static_cast<double>(p.x) * p.x + static_cast<double>(p.y) * p.y +
                                   static_cast<double>(p.z) * p.z);
        asset->distance()[static_cast<size_t>(i) + dims[0] * (j + static_cast<size_t>(dims[1]) * k)] =
            static_cast<float>(2.5 * (r - radius) + 0.002 * std::sin(300.0 * p.x));
      }
  return asset;
}
