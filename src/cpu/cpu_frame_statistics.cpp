// The CPU backend's frame statistics: the twin of cuda/frame_statistics.cu.
#include <algorithm>

#include "cpu_backend_impl.h"

namespace sph {

// Density and neighbour statistics of the last density evaluation.
void CpuBackend::summarize(FrameReport& report) const {
  if (count_ == 0) return;
  double sum = 0.0, neighbor_sum = 0.0;
  float lo = density_.data[0], hi = density_.data[0];
  uint32_t neighbor_max = 0;
  for (uint32_t i = 0; i < count_; ++i) {
    const float d = density_.data[i];
    sum += d;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    neighbor_sum += neighbors_.data[i];
    neighbor_max = std::max(neighbor_max, neighbors_.data[i]);
  }
  report.density_min = lo;
  report.density_max = hi;
  report.density_mean = static_cast<float>(sum / count_);
  report.neighbors_mean = static_cast<float>(neighbor_sum / count_);
  report.neighbors_max = neighbor_max;
}

}  // namespace sph
