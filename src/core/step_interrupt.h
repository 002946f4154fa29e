// SPDX-License-Identifier: MIT
// What may stop a step early: a wall-clock deadline and a cancel flag that another thread can
// raise (sph_world_set_step_budget, sph_world_cancel_step). A backend checks it at substep
// boundaries only, so a step it stops leaves the world as after its last whole substep, like a
// step that ran out of max_substeps (the step returns INCOMPLETE).
#pragma once

#include <stdint.h>

#include <atomic>
#include <chrono>

namespace sph {

struct StepInterrupt {
  using Clock = std::chrono::steady_clock;
  Clock::time_point deadline = Clock::time_point::max();
  const std::atomic<uint32_t>* cancel = nullptr;  // raised: stop; owned by the caller

  bool has_deadline() const { return deadline != Clock::time_point::max(); }
  bool requested() const {
    if (cancel && cancel->load(std::memory_order_relaxed) != 0) return true;
    return has_deadline() && Clock::now() >= deadline;
  }
};

}  // namespace sph
