// SPDX-License-Identifier: MIT
// A signed-distance grid asset: distances (negative inside) at voxel centres with an
// index-to-local affine map, and optional per-voxel surface velocity and friction. Assets are
// shared: colliders, sources, sinks and fields in any world of a context hold references.
#pragma once

#include <stdint.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "../physics/sdf_sampling.h"
#include "host_memory.h"
#include "voxel_box.h"

namespace sph {

class SdfAsset {
 public:
  // Throws Error(InvalidArgument) for a singular or non-finite affine map or empty dims.
  SdfAsset(int32_t nx, int32_t ny, int32_t nz, const Affine3x4& index_to_local);

  int32_t nx() const { return nx_; }
  int32_t ny() const { return ny_; }
  int32_t nz() const { return nz_; }
  uint64_t voxel_count() const { return static_cast<uint64_t>(nx_) * ny_ * nz_; }
  const Affine3x4& index_to_local() const { return index_to_local_; }
  // The longest voxel edge in local units: the largest column norm of the index-to-local map's
  // linear part (the shortest is the sampling view's min_voxel_size).
  double max_voxel_size() const;

  HostVector<float>& distance() { return distance_; }
  HostVector<Vec3>& velocity() { return velocity_; }   // empty when the asset has none
  HostVector<float>& friction() { return friction_; }  // empty when the asset has none
  const HostVector<float>& distance() const { return distance_; }
  const HostVector<Vec3>& velocity() const { return velocity_; }
  const HostVector<float>& friction() const { return friction_; }

  bool has_velocity() const { return !velocity_.empty(); }
  // True when a velocity field exists and any of it is non-zero.
  bool has_moving_surface() const;

  // A view over host memory (the CPU backend samples it directly).
  SdfGridView host_view() const;
  SdfGridView view_with(const float* distance, const Vec3* velocity, const float* friction) const;

  // Bumped on every change, so device copies know when to refresh.
  uint64_t version() const { return version_.load(); }
  // A change of unknown extent: every voxel's distance may have changed.
  void touch() { record_change(whole_grid()); }
  // A change whose distances changed only within `distance_box` (empty: another channel's).
  void record_change(const VoxelBox& distance_box);
  // The box holding every distance changed since `version` (empty: none), or false when the
  // changes since then are no longer all recorded (the last kChangesKept are).
  bool distance_changed_since(uint64_t version, VoxelBox* out) const;
  VoxelBox whole_grid() const;
  uint64_t uid() const { return uid_; }
  size_t bytes() const {
    return distance_.size() * sizeof(float) + velocity_.size() * sizeof(Vec3) +
           friction_.size() * sizeof(float);
  }

 private:
  int32_t nx_, ny_, nz_;
  Affine3x4 index_to_local_;
  Affine3x4 local_to_index_;
  float min_voxel_size_;
  HostVector<float> distance_;
  HostVector<Vec3> velocity_;
  HostVector<float> friction_;
  std::atomic<uint64_t> version_{1};
  uint64_t uid_;
  // The last changes' distance boxes, by the version each made (a ring).
  static constexpr int kChangesKept = 16;
  struct Change {
    uint64_t version = 0;
    VoxelBox distance_box;
  };
  mutable std::mutex changes_mutex_;
  Change changes_[kChangesKept];
};

// A new asset, the object and its grids from the allocator current on this thread (the engine's,
// when its context has one: core/host_memory.h).
template <class... Args>
std::shared_ptr<SdfAsset> make_sdf_asset(Args&&... args) {
  return std::allocate_shared<SdfAsset>(HostAllocator<SdfAsset>(), std::forward<Args>(args)...);
}

}  // namespace sph
