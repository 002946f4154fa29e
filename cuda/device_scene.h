// SPDX-License-Identifier: MIT
// The scene on the device, per world: device copies of the SDF assets the scene uses (one
// copy per asset, shared by every collider, field and sink that uses it), and the per-frame
// arrays of collider, force-field and sink views whose SdfGridViews point at those copies.
// Everything here is updated on the host side of a frame, before the frame's graph (or its
// stream fallback) is launched: nothing inside the frame allocates or copies scene data.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <unordered_map>
#include <vector>

#include "../src/core/scene_frame.h"
#include "device_array.h"
#include "substep_kernels.h"

namespace sph {

// Device copies of SDF assets, keyed by SdfAsset::uid() and refreshed when version() changes.
// Bytes per asset: 4 per voxel (distance) + 12 (velocity channel, if any) + 4 (friction
// channel, if any).
class DeviceSdfCache {
 public:
  // Marks the start of a frame's binding: assets not bound again until end_frame() are dropped.
  void begin_frame() { ++frame_; }
  // The device view of an asset, uploading it (on `stream`) when new or changed.
  SdfGridView bind(const SdfAsset& asset, cudaStream_t stream);
  void end_frame();
  uint64_t bytes() const;

 private:
  struct Entry {
    uint64_t version = 0;
    uint64_t last_frame = 0;
    DeviceArray<float> distance;
    DeviceArray<Vec3> velocity;
    DeviceArray<float> friction;
  };
  std::unordered_map<uint64_t, Entry> entries_;
  uint64_t frame_ = 0;
};

// The views of one frame in device memory, grown (never shrunk) as the scene grows.
class DeviceSceneBuffer {
 public:
  // Uploads the views (SdfGridViews already bound to device memory) on `stream`; returns what
  // the kernels get.
  DeviceScene upload(const SceneFrame& scene, float kernel_radius, cudaStream_t stream);
  const SinkView* sinks() const { return sinks_.get(); }
  uint64_t bytes() const { return colliders_.bytes() + fields_.bytes() + sinks_.bytes(); }

 private:
  DeviceArray<ColliderView> colliders_;
  DeviceArray<ForceFieldView> fields_;
  DeviceArray<SinkView> sinks_;
  HostVector<ColliderView> host_colliders_;
  HostVector<ForceFieldView> host_fields_;
  HostVector<SinkView> host_sinks_;
};

}  // namespace sph
