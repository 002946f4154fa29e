// SPDX-License-Identifier: MIT
// The CPU backend's frame statistics: the density record (src/core/density_record.h) of the
// last density evaluation, tallied in storage order. The twin of cuda/frame_statistics.cu.
#include "../core/density_record.h"
#include "cpu_backend_impl.h"

namespace sph {

void CpuBackend::summarize(FrameReport& report) const {
  const float* density = density_.data();
  const uint32_t* neighbors = neighbors_.data();
  DensityTally total = empty_tally();
  for (uint32_t i = 0; i < count_; ++i) combine(total, particle_tally(density[i], neighbors[i]));
  report_density(finish_record(total, count_), report);
}

}  // namespace sph
