// SPDX-License-Identifier: MIT
// The CPU backend's springs (SPH_FEATURE_SPRINGS; the physics is src/physics/springs.h): the
// twin of cuda/device_springs.cu.
#include "cpu_backend_impl.h"

namespace sph {

// Springs (SPH_FEATURE_SPRINGS), after the sort: the particles that wait for springs make
// them (two passes, springs.h), then every particle gathers its spring acceleration into a
// side array that the force pass adds. first_evaluation: the substep's first force
// evaluation, where the rest lengths flow (plasticity).
void CpuBackend::spring_pass(float dt, bool first_evaluation, FrameReport& report) {
  if (!springs_) return;
  const auto t = Clock::now();
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  SpringList* lists = springs_.data();
  const SpringConstants& c = spring_constants_;
  if (link_from_[0] != kNoPendingLinks) {
    const GridView view = grid_.view();
    const uint32_t* ids = id_.data();
    const uint32_t from = link_from_[0];
    uint32_t* candidates = spring_candidates_.data();
    parallel().for_each(count_, [&](uint32_t i) {
      spring_candidates(c, view, pos, ids, from, lists[i], static_cast<uint32_t>(i),
                        candidates + static_cast<size_t>(i) * kSpringSlots);
    });
    parallel().for_each(
        count_, [&](uint32_t i) { spring_link(pos, candidates, static_cast<uint32_t>(i), lists[i]); });
    link_from_[0] = kNoPendingLinks;
  }
  Float4* out = spring_acceleration_.data();  // w unused
  if (first_evaluation) {
    parallel().for_each(count_, [&](uint32_t i) {
      out[i] = make_float4_record(
          spring_acceleration<true>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt), 0.0f);
    });
  } else {
    parallel().for_each(count_, [&](uint32_t i) {
      out[i] = make_float4_record(
          spring_acceleration<false>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt), 0.0f);
    });
  }
  report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
}

}  // namespace sph
