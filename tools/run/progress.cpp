// SPDX-License-Identifier: MIT
#include "progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sph_tools {

std::string format_duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  if (s >= 3600)
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
  return text;
}

Progress::Progress(uint32_t total, bool tty, bool quiet)
    : total_(total), tty_(tty), quiet_(quiet), start_(std::chrono::steady_clock::now()) {}

void Progress::frame_done(const FrameReport& r) {
  if (quiet_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double per_frame = r.frame > 0 ? elapsed / r.frame : 0.0;
  const double eta = per_frame * (total_ - r.frame);
  // DFSPH's density iterations a substep: how hard the solve works for the frame's bound.
  char solve[48] = "";
  if (r.density_iterations > 0 && r.substeps > 0)
    std::snprintf(solve, sizeof solve, tty_ ? "  %.1f it/substep" : " (%.1f density iterations a substep)",
                  static_cast<double>(r.density_iterations) / r.substeps);
  if (!tty_) {
    std::fprintf(stderr, "frame %u/%u: %u particles, %u substeps%s, step %.1f ms, output %.1f ms, eta %s\n",
                 r.frame, total_, r.particles, r.substeps, solve, r.step_ms, r.output_ms,
                 format_duration(eta).c_str());
    std::fflush(stderr);
    return;
  }
  // Redraw at most 10 times a second, and always at the last frame.
  if (r.frame != total_ && last_draw_s_ >= 0.0 && elapsed - last_draw_s_ < 0.1) return;
  last_draw_s_ = elapsed;
  const int width = 24;
  const double share = total_ > 0 ? static_cast<double>(r.frame) / total_ : 1.0;
  const int filled = static_cast<int>(share * width);
  char bar[width + 1];
  for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : (i == filled ? '>' : '.');
  bar[width] = '\0';
  std::fprintf(stderr, "\r\033[Kframe %u/%u [%s] %3.0f%%  %u particles  %u substeps%s  %.0f ms/frame  ETA %s",
               r.frame, total_, bar, 100.0 * share, r.particles, r.substeps, solve, r.step_ms + r.output_ms,
               format_duration(eta).c_str());
  std::fflush(stderr);
  bar_shown_ = true;
}

void Progress::note(const std::string& text) {
  if (tty_ && bar_shown_) std::fputs("\r\033[K", stderr);
  std::fprintf(stderr, "%s\n", text.c_str());
  last_draw_s_ = -1.0;  // redraw the bar at the next frame
}

void Progress::finish() {
  if (tty_ && bar_shown_) std::fputs("\n", stderr);
  bar_shown_ = false;
  std::fflush(stderr);
}

}  // namespace sph_tools
