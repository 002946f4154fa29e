// SPDX-License-Identifier: MIT
// The density record of a frame, written once for both backends: density min/mean/max and the
// neighbour counts of its last density evaluation (sph_stats). Each particle contributes a tally;
// tallies combine in any grouping (the CPU backend adds them in storage order, the CUDA backend
// in a fixed tree, frame_statistics.cu) and the record is finished from the total.
#pragma once

#include <float.h>
#include <stdint.h>

#include "../physics/host_device.h"
#include "frame_report.h"

namespace sph {

struct DensityTally {
  double density_sum;
  unsigned long long neighbor_sum;
  float density_min;
  float density_max;
  uint32_t neighbor_max;
  uint32_t pad;
};

struct DensityRecord {
  float density_min;
  float density_mean;
  float density_max;
  float neighbors_mean;
  uint32_t neighbors_max;
};

SPH_HD DensityTally empty_tally() { return DensityTally{0.0, 0ull, FLT_MAX, -FLT_MAX, 0u, 0u}; }

SPH_HD DensityTally particle_tally(float density, uint32_t neighbors) {
  return DensityTally{density, neighbors, density, density, neighbors, 0u};
}

SPH_HD void combine(DensityTally& a, const DensityTally& b) {
  a.density_sum += b.density_sum;
  a.neighbor_sum += b.neighbor_sum;
  a.density_min = b.density_min < a.density_min ? b.density_min : a.density_min;
  a.density_max = a.density_max < b.density_max ? b.density_max : a.density_max;
  a.neighbor_max = a.neighbor_max < b.neighbor_max ? b.neighbor_max : a.neighbor_max;
}

// The record of n particles (all zero for none).
SPH_HD DensityRecord finish_record(const DensityTally& t, uint32_t n) {
  const bool any = n > 0;
  DensityRecord r;
  r.density_min = any ? t.density_min : 0.0f;
  r.density_max = any ? t.density_max : 0.0f;
  r.density_mean = any ? static_cast<float>(t.density_sum / n) : 0.0f;
  r.neighbors_mean = any ? static_cast<float>(static_cast<double>(t.neighbor_sum) / n) : 0.0f;
  r.neighbors_max = any ? t.neighbor_max : 0u;
  return r;
}

inline void report_density(const DensityRecord& r, FrameReport& report) {
  report.density_min = r.density_min;
  report.density_mean = r.density_mean;
  report.density_max = r.density_max;
  report.neighbors_mean = r.neighbors_mean;
  report.neighbors_max = r.neighbors_max;
}

}  // namespace sph
