// SPDX-License-Identifier: MIT
#include "scene_objects.h"

#include <algorithm>
#include <limits>

#include <string>

#include "fcc_lattice.h"
#include "status.h"

namespace sph {

HostVector<Vec3> lattice_inside(const SdfAsset& region, float spacing, uint64_t max_points) {
  // The grid's box in the local frame: the bounding box of its eight index-space corners.
  Vec3 lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
          std::numeric_limits<float>::max()};
  Vec3 hi{-lo.x, -lo.y, -lo.z};
  for (int c = 0; c < 8; ++c) {
    const Vec3 idx{(c & 1) ? static_cast<float>(region.nx() - 1) : 0.0f,
                   (c & 2) ? static_cast<float>(region.ny() - 1) : 0.0f,
                   (c & 4) ? static_cast<float>(region.nz() - 1) : 0.0f};
    const Vec3 p = apply_affine(region.index_to_local(), idx);
    lo = Vec3{std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = Vec3{std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  // fcc_points_in_box keeps half a spacing from each face; widen so the lattice reaches the box.
  const float m = 0.5f * spacing;
  const uint64_t candidates = fcc_box_point_count(lo - Vec3{m, m, m}, hi + Vec3{m, m, m}, spacing);
  if (candidates > max_points)
    throw Error(Status::Capacity, "the region's box holds " + std::to_string(candidates) +
                                      " lattice points at this spacing, more than the limit of " +
                                      std::to_string(max_points));
  const HostVector<Vec3> box = fcc_points_in_box(lo - Vec3{m, m, m}, hi + Vec3{m, m, m}, spacing);
  const SdfGridView view = region.host_view();
  HostVector<Vec3> inside;
  for (const Vec3& p : box)
    if (sample_distance(view, p) < 0.0f) inside.push_back(p);
  return inside;
}

}  // namespace sph
