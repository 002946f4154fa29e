// SPDX-License-Identifier: MIT
// The CPU backend's stage timer (FrameReport::stage_ms): a stage's wall time and, on a distributed
// world's rank, the share of it spent inside the rank transport's calls (the wait for the slowest
// rank and the transfer) and of that the waits at the barriers MpiTransport::wait_at_barriers puts
// before them, which bench/mpi_halo tells from the rank's own work (issue 19).
#pragma once

#include <chrono>

#include "../core/distributed.h"
#include "../core/frame_report.h"
#include "../core/rank_transport.h"

namespace sph {

using Clock = std::chrono::steady_clock;

inline double elapsed_ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

// Adds the wall time since its last lap to a phase of a CPU rank's hash+sort stage (HaloPhaseTimes,
// bench/mpi_halo's table).
class PhaseClock {
 public:
  explicit PhaseClock(HaloPhaseTimes& times) : times_(times), at_(Clock::now()) {}
  void lap(HaloPhase phase) {
    const Clock::time_point now = Clock::now();
    times_.ms[phase] += std::chrono::duration<double, std::milli>(now - at_).count();
    at_ = now;
  }

 private:
  HaloPhaseTimes& times_;
  Clock::time_point at_;
};

// A stage's start: the clock and the transport's running times (zero without a transport).
struct StageStart {
  Clock::time_point wall;
  double transport_ms = 0.0;
  double wait_ms = 0.0;
};

// transport: the rank's, or null on an undivided world (or one whose transport does not time).
inline StageStart start_stage(const RankTransport* transport) {
  StageStart s{Clock::now()};
  if (const TransportTimes* t = transport ? transport->times() : nullptr) {
    s.transport_ms = t->total_ms;
    s.wait_ms = t->ms[kCallBarrier];
  }
  return s;
}

inline void end_stage(FrameReport& report, StageIndex stage, const StageStart& start,
                      const RankTransport* transport) {
  report.stage_ms[stage] += static_cast<float>(elapsed_ms(start.wall));
  if (const TransportTimes* t = transport ? transport->times() : nullptr) {
    report.transport_ms[stage] += static_cast<float>(t->total_ms - start.transport_ms);
    report.transport_wait_ms[stage] += static_cast<float>(t->ms[kCallBarrier] - start.wait_ms);
  }
}

}  // namespace sph
