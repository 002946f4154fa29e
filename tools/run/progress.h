// SPDX-License-Identifier: MIT
// Progress of a run: a one-line bar redrawn in place on a terminal, plain lines otherwise.
#ifndef SPH_TOOLS_PROGRESS_H
#define SPH_TOOLS_PROGRESS_H

#include <chrono>
#include <cstdint>
#include <string>

namespace sph_tools {

struct FrameReport {
  uint32_t frame = 0;
  uint32_t particles = 0;
  uint32_t substeps = 0;
  double step_ms = 0.0;             // wall time of the frame's simulation
  double output_ms = 0.0;           // wall time of its files
  uint32_t density_iterations = 0;  // DFSPH: the frame's density solve iterations (0: no solve ran)
};

class Progress {
 public:
  // total: frames to simulate. tty: redraw in place. quiet: show nothing.
  Progress(uint32_t total, bool tty, bool quiet);
  void frame_done(const FrameReport& report);
  // A message between progress lines (a warning); clears the bar first.
  void note(const std::string& text);
  // Ends the bar's line.
  void finish();

 private:
  uint32_t total_;
  bool tty_, quiet_;
  bool bar_shown_ = false;
  std::chrono::steady_clock::time_point start_;
  double last_draw_s_ = -1.0;
};

// Seconds as "1:05" or "1:02:03".
std::string format_duration(double seconds);

}  // namespace sph_tools

#endif
