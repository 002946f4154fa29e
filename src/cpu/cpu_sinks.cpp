// SPDX-License-Identifier: MIT
// The CPU backend's sinks: the twin of cuda/device_sinks.cu.
#include "cpu_backend_impl.h"

namespace sph {

// Removes particles inside any sink, keeping the order of the rest; records their ids.
void CpuBackend::apply_sinks(const SceneFrame& scene, FrameReport& report) {
  const auto t = stage_start();
  keep_order_.clear();
  const Float4* position = position_.data();
  for (uint32_t i = 0; i < count_; ++i) {
    const Vec3 x = xyz(position[i]);
    bool removed = false;
    for (size_t s = 0; s < scene.sinks.size() && !removed; ++s)
      if (sink_removes(scene.sinks[s].view, x)) {
        removed = true;
        ++report.removed_by_sink[s];
        report.removed_ids.push_back(id_[i]);
      }
    if (!removed) keep_order_.push_back(i);
  }
  if (keep_order_.size() != count_) {
    store_.permute(keep_order_.data(), keep_order_.size(), parallel());
    count_ = static_cast<uint32_t>(keep_order_.size());
    store_.resize(count_);
  }
  end_stage(report, kStageEmit, t);
}

}  // namespace sph
