// SPDX-License-Identifier: MIT
// The CUDA backend's boundary-density maps (SPH_FEATURE_BOUNDARY_DENSITY; the physics is
// src/physics/boundary_map.h): one map per SDF asset the world's colliders use, computed on the
// device from the asset's device copy (DeviceSdfCache) for the world's kernel radius, one thread
// per voxel, when a collider first steps with the asset and again after every change of it
// (SdfAsset::version), and dropped when no collider uses the asset any more (the twin of
// src/cpu/cpu_boundary_maps.h). Computed on the world's stream before the frame is launched.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <map>
#include <utility>

#include "../src/core/sdf_asset.h"
#include "../src/physics/float4_types.h"
#include "device_array.h"

namespace sph {

class DeviceBoundaryMaps {
 public:
  void begin_frame() { ++frame_; }
  // The map of an asset for kernel radius h and SDF level `level` (boundary_map.h); `sdf` is the
  // asset's device view.
  const Float4* bind(const SdfAsset& asset, const SdfGridView& sdf, float h, float level,
                     cudaStream_t stream);
  void end_frame();
  // 16 bytes per voxel of every map held.
  uint64_t bytes() const;

 private:
  struct Entry {
    uint64_t version = 0;
    float kernel_radius = 0.0f;
    uint64_t last_frame = 0;
    DeviceArray<Float4> correction;
  };
  std::map<std::pair<uint64_t, float>, Entry> entries_;  // by asset uid and level
  uint64_t frame_ = 0;
};

}  // namespace sph
