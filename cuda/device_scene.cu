// SPDX-License-Identifier: MIT
#include "device_scene.h"

namespace sph {
namespace {

template <class T>
void upload_array(DeviceArray<T>& dst, const HostVector<T>& src, cudaStream_t stream, const char* what) {
  if (src.empty()) return;
  if (dst.size() < src.size()) dst.allocate(src.size(), what);
  cuda_check(cudaMemcpyAsync(dst.get(), src.data(), sizeof(T) * src.size(), cudaMemcpyHostToDevice, stream),
             what);
}

}  // namespace

SdfGridView DeviceSdfCache::bind(const SdfAsset& asset, cudaStream_t stream) {
  Entry& e = entries_[asset.uid()];
  e.last_frame = frame_;
  const uint64_t version = asset.version();
  if (e.version != version || e.distance.size() != asset.distance().size() ||
      e.velocity.size() != asset.velocity().size() || e.friction.size() != asset.friction().size()) {
    e.version = 0;  // until the copies below are all enqueued
    upload_array(e.distance, asset.distance(), stream, "device copy of an SDF's distances");
    upload_array(e.velocity, asset.velocity(), stream, "device copy of an SDF's velocities");
    upload_array(e.friction, asset.friction(), stream, "device copy of an SDF's friction");
    e.version = version;
  }
  return asset.view_with(e.distance.get(), asset.has_velocity() ? e.velocity.get() : nullptr,
                         asset.friction().empty() ? nullptr : e.friction.get());
}

void DeviceSdfCache::end_frame() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.last_frame != frame_)
      it = entries_.erase(it);
    else
      ++it;
  }
}

uint64_t DeviceSdfCache::bytes() const {
  uint64_t total = 0;
  for (const auto& kv : entries_)
    total += kv.second.distance.bytes() + kv.second.velocity.bytes() + kv.second.friction.bytes();
  return total;
}

DeviceScene DeviceSceneBuffer::upload(const SceneFrame& scene, float kernel_radius, cudaStream_t stream) {
  host_colliders_.clear();
  host_fields_.clear();
  host_sinks_.clear();
  for (const ColliderFrame& c : scene.colliders) host_colliders_.push_back(c.view);
  for (const ForceFieldFrame& f : scene.fields) host_fields_.push_back(f.view);
  for (const SinkFrame& s : scene.sinks) host_sinks_.push_back(s.view);
  upload_array(colliders_, host_colliders_, stream, "device collider views");
  upload_array(fields_, host_fields_, stream, "device force-field views");
  upload_array(sinks_, host_sinks_, stream, "device sink views");
  DeviceScene d;
  d.colliders = host_colliders_.empty() ? nullptr : colliders_.get();
  d.fields = host_fields_.empty() ? nullptr : fields_.get();
  d.collider_count = static_cast<uint32_t>(host_colliders_.size());
  d.field_count = static_cast<uint32_t>(host_fields_.size());
  d.kernel_radius = kernel_radius;
  return d;
}

}  // namespace sph
