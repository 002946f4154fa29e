// SPDX-License-Identifier: MIT
#include "cpu_boundary_maps.h"

#include "../physics/boundary_map.h"

namespace sph {

HostVector<Float4> compute_boundary_map(const SdfAsset& asset, float h, float level,
                                        const CpuParallel& parallel) {
  HostVector<Float4> map(asset.voxel_count(), Float4{0.0f, 0.0f, 0.0f, 0.0f});
  const SdfGridView g = asset.host_view();
  const Affine3x4 index_to_local = asset.index_to_local();
  const size_t planes = static_cast<size_t>(asset.ny()) * static_cast<size_t>(asset.nz());
  const size_t nx = static_cast<size_t>(asset.nx());
  // One (j, k) row of voxels per item, four rows a block: the band's rows cost far more than the
  // rest, so small blocks go out on demand.
  parallel.for_blocks(planes, 4, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const int32_t j = static_cast<int32_t>(row % asset.ny()), k = static_cast<int32_t>(row / asset.ny());
      for (int32_t i = 0; i < asset.nx(); ++i)
        map[static_cast<size_t>(i) + nx * row].x =
            boundary_map_correction(g, index_to_local, i, j, k, h, level);
    }
  });
  // The slopes from the values: all values are in place before any slope is written, and a slope
  // writes only its own voxel's gradient channels.
  parallel.for_blocks(planes, 64, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const int32_t j = static_cast<int32_t>(row % asset.ny()), k = static_cast<int32_t>(row / asset.ny());
      for (int32_t i = 0; i < asset.nx(); ++i) {
        const Vec3 s = boundary_map_slope(g, map.data(), i, j, k, h, level);
        Float4& m = map[static_cast<size_t>(i) + nx * row];
        m.y = s.x, m.z = s.y, m.w = s.z;
      }
    }
  });
  return map;
}

const Float4* CpuBoundaryMaps::bind(const SdfAsset& asset, float h, float level,
                                    const CpuParallel& parallel) {
  Entry& e = entries_[std::make_pair(asset.uid(), level)];
  e.last_frame = frame_;
  if (e.version != asset.version() || e.kernel_radius != h || e.correction.size() != asset.voxel_count()) {
    e.version = 0;  // until the map below is complete
    e.correction = compute_boundary_map(asset, h, level, parallel);
    e.kernel_radius = h;
    e.version = asset.version();
    ++builds_;
  }
  return e.correction.data();
}

void CpuBoundaryMaps::end_frame() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.last_frame != frame_)
      it = entries_.erase(it);
    else
      ++it;
  }
}

uint64_t CpuBoundaryMaps::bytes() const {
  uint64_t total = 0;
  for (const auto& kv : entries_) total += kv.second.correction.size() * sizeof(Float4);
  return total;
}

}  // namespace sph
