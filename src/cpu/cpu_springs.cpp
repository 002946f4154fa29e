// SPDX-License-Identifier: MIT
// The CPU backend's springs (SPH_FEATURE_SPRINGS; the physics is src/physics/springs.h): the
// twin of cuda/device_springs.cu.
#include <algorithm>

#include "cpu_backend_impl.h"

namespace sph {

// Springs (SPH_FEATURE_SPRINGS), after the sort: the particles that wait for springs make
// them (two passes, springs.h), then every particle gathers its spring acceleration into a
// side array that the force pass adds. first_evaluation: the substep's first force
// evaluation, where the rest lengths flow (plasticity).
void CpuBackend::spring_pass(float dt, bool first_evaluation, FrameReport& report) {
  if (!springs_) return;
  const auto t = stage_start();
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  SpringList* lists = springs_.data();
  const SpringConstants& c = spring_constants_;
  // A distributed world's ghosts (origin != 0) neither link nor move: their lists name partners
  // by id, and their owners compute their springs (cpu_halo_springs.cpp).
  const uint32_t* origin = origins();  // null unless distributed
  if (link_from_[0] != kNoPendingLinks) {
    const GridView view = grid_.view();
    const uint32_t* ids = id_.data();
    const uint32_t from = link_from_[0];
    uint32_t* candidates = spring_candidates_.data();
    parallel().for_each(count_, [&](uint32_t i) {
      uint32_t* mine = candidates + static_cast<size_t>(i) * kSpringSlots;
      if (origin && origin[i]) {
        std::fill(mine, mine + kSpringSlots, kNoSpring);  // (a ghost's come from its owner)
        return;
      }
      spring_candidates(c, view, pos, ids, from, lists[i], static_cast<uint32_t>(i), mine);
    });
    if (rank_) rank_->share_spring_candidates();
    parallel().for_each(count_, [&](uint32_t i) {
      if (!(origin && origin[i])) spring_link(pos, candidates, static_cast<uint32_t>(i), lists[i]);
    });
    link_from_[0] = kNoPendingLinks;
  }
  Float4* out = spring_acceleration_.data();  // w unused
  const Float4 none = make_float4_record(Vec3{0.0f, 0.0f, 0.0f}, 0.0f);
  if (first_evaluation) {
    parallel().for_each(count_, [&](uint32_t i) {
      out[i] =
          origin && origin[i]
              ? none
              : make_float4_record(
                    spring_acceleration<true>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt), 0.0f);
    });
  } else {
    parallel().for_each(count_, [&](uint32_t i) {
      out[i] =
          origin && origin[i]
              ? none
              : make_float4_record(
                    spring_acceleration<false>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt), 0.0f);
    });
  }
  end_stage(report, kStageForces, t);
}

}  // namespace sph
