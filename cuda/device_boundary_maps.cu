// SPDX-License-Identifier: MIT
#include "../src/physics/boundary_map.h"
#include "device_boundary_maps.h"
#include "kernel_launch.h"

namespace sph {
namespace {

__global__ void boundary_map_kernel(SdfGridView sdf, Affine3x4 index_to_local, float h, float level,
                                    Float4* map, uint64_t voxels) {
  const uint64_t v = static_cast<uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (v >= voxels) return;
  const uint64_t row = v / static_cast<uint64_t>(sdf.nx);
  const int32_t i = static_cast<int32_t>(v % static_cast<uint64_t>(sdf.nx));
  const int32_t j = static_cast<int32_t>(row % static_cast<uint64_t>(sdf.ny));
  const int32_t k = static_cast<int32_t>(row / static_cast<uint64_t>(sdf.ny));
  map[v] =
      Float4{boundary_map_correction(sdf, index_to_local, i, j, k, h, level, SdfSlope{}), 0.0f, 0.0f, 0.0f};
}

// After boundary_map_kernel (every value in place): each voxel's slopes from its neighbours'
// values, written to its own gradient channels only.
__global__ void boundary_map_slope_kernel(SdfGridView sdf, float h, float level, Float4* map,
                                          uint64_t voxels) {
  const uint64_t v = static_cast<uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (v >= voxels) return;
  const uint64_t row = v / static_cast<uint64_t>(sdf.nx);
  const int32_t i = static_cast<int32_t>(v % static_cast<uint64_t>(sdf.nx));
  const int32_t j = static_cast<int32_t>(row % static_cast<uint64_t>(sdf.ny));
  const int32_t k = static_cast<int32_t>(row / static_cast<uint64_t>(sdf.ny));
  const Vec3 s = boundary_map_slope(sdf, map, i, j, k, h, level);
  map[v].y = s.x;
  map[v].z = s.y;
  map[v].w = s.z;
}

}  // namespace

const Float4* DeviceBoundaryMaps::bind(const SdfAsset& asset, const SdfGridView& sdf, float h, float level,
                                       cudaStream_t stream) {
  Entry& e = entries_[std::make_pair(asset.uid(), level)];
  e.last_frame = frame_;
  const uint64_t voxels = asset.voxel_count();
  if (e.version != asset.version() || e.kernel_radius != h || e.correction.size() != voxels) {
    e.version = 0;  // until the kernel below is enqueued
    if (e.correction.size() != voxels) e.correction.allocate(voxels, "boundary-density map of an SDF");
    const unsigned threads = 128;
    const unsigned blocks = static_cast<unsigned>((voxels + threads - 1) / threads);
    boundary_map_kernel<<<blocks, threads, 0, stream>>>(sdf, asset.index_to_local(), h, level,
                                                        e.correction.get(), voxels);
    check_launch("boundary_map_kernel");
    boundary_map_slope_kernel<<<blocks, threads, 0, stream>>>(sdf, h, level, e.correction.get(), voxels);
    check_launch("boundary_map_slope_kernel");
    e.kernel_radius = h;
    e.version = asset.version();
  }
  return e.correction.get();
}

void DeviceBoundaryMaps::end_frame() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.last_frame != frame_)
      it = entries_.erase(it);
    else
      ++it;
  }
}

uint64_t DeviceBoundaryMaps::bytes() const {
  uint64_t total = 0;
  for (const auto& kv : entries_) total += kv.second.correction.bytes();
  return total;
}

}  // namespace sph
