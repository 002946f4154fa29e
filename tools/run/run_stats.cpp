// SPDX-License-Identifier: MIT
#include "run_stats.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace sph_tools {

void RunStats::add_frame(const sph_stats& s, double step_wall_ms, double output_wall_ms) {
  if (frames_ == 0 || s.dt_min < dt_min_) dt_min_ = s.dt_min;
  dt_max_ = std::max(dt_max_, s.dt_max);
  speed_max_ = std::max(speed_max_, s.max_speed);
  particles_max_ = std::max(particles_max_, s.particle_count);
  substeps_ += s.substeps;
  step_ms_ += step_wall_ms;
  output_ms_ += output_wall_ms;
  for (int i = 0; i < SPH_STAGE_COUNT; ++i) stage_ms_[i] += s.stage_ms[i];
  last_ = s;
  ++frames_;
  if (s.pressure_iterations == 0) return;  // no DFSPH solve ran (a WCSPH world, or no substep)
  Solves& d = solves_;
  d.substeps += s.substeps;
  d.density_iterations += s.pressure_iterations;
  d.divergence_iterations += s.divergence_iterations;
  d.density_iterations_max = std::max(d.density_iterations_max, s.pressure_iterations_max);
  d.divergence_iterations_max = std::max(d.divergence_iterations_max, s.divergence_iterations_max);
  d.density_error_sum += static_cast<double>(s.density_error_mean) * s.substeps;
  d.divergence_error_sum += static_cast<double>(s.divergence_error_mean) * s.substeps;
  d.density_error_max = std::max(d.density_error_max, s.density_error_max);
  d.divergence_error_max = std::max(d.divergence_error_max, s.divergence_error_max);
  d.density_error_largest = std::max(d.density_error_largest, s.density_error_largest);
  d.density_capped += s.pressure_solves_capped;
  d.divergence_capped += s.divergence_solves_capped;
  d.guarded += s.pressure_solves_guarded;
}

void RunStats::print(std::FILE* out, const std::string& what, const std::string& backend,
                     double wall_s) const {
  std::fprintf(out, "sph-run: %s in %.1f s on the %s backend\n", what.c_str(), wall_s, backend.c_str());
  if (frames_ == 0) {
    std::fprintf(out, "  output %.1f ms\n", output_ms_);
    return;
  }
  const double written = frames_ + 1.0;
  std::fprintf(out,
               "  time per frame: %.1f ms simulating, %.1f ms writing output (particles %.1f, surface %.1f, "
               "preview %.1f)\n",
               step_ms_ / frames_, output_ms_ / written, particles_ms_ / written, surface_ms_ / written,
               preview_ms_ / written);
  std::fprintf(out,
               "  particles: %u at the end, %u at most; substeps %llu (%.1f per frame, dt %.3g..%.3g s)\n",
               last_.particle_count, particles_max_, static_cast<unsigned long long>(substeps_),
               static_cast<double>(substeps_) / frames_, dt_min_, dt_max_);
  std::fprintf(out,
               "  last frame: density %.1f / %.1f / %.1f kg/m^3 (min/mean/max), %.1f neighbours (max %u), "
               "max speed %.2f m/s (%.2f in the run)\n",
               last_.density_min, last_.density_mean, last_.density_max, last_.neighbors_mean,
               last_.neighbors_max, last_.max_speed, speed_max_);
  static const char* kStages[SPH_STAGE_COUNT] = {"hash+sort", "cells",   "density", "forces",
                                                 "integrate", "collide", "emit",    "other"};
  double total = 0.0;
  for (double ms : stage_ms_) total += ms;
  if (total > 0.0) {
    std::fprintf(out, "  stages:");
    for (int i = 0; i < SPH_STAGE_COUNT; ++i)
      std::fprintf(out, " %s %.0f%%", kStages[i], 100.0 * stage_ms_[i] / total);
    std::fprintf(out, "\n");
  }
  print_solves(out);
  std::fprintf(out, "  world memory: %.1f MiB\n",
               static_cast<double>(last_.memory_bytes) / (1024.0 * 1024.0));
}

void RunStats::print_solves(std::FILE* out) const {
  if (solves_.substeps == 0) return;
  const Solves& d = solves_;
  const double n = static_cast<double>(d.substeps);
  std::fprintf(
      out,
      "  DFSPH density solve: %.2f iterations a substep (most %u), error %.4f %% mean (%.4f %% in the "
      "worst substep, %.3f %% the largest particle's)\n",
      d.density_iterations / n, d.density_iterations_max, 100.0 * d.density_error_sum / n,
      100.0 * d.density_error_max, 100.0 * d.density_error_largest);
  if (d.divergence_iterations == 0)  // (SPH_DFSPH_SKIP_DIVERGENCE_SOLVE)
    std::fprintf(out, "  DFSPH divergence solve: off\n");
  else
    std::fprintf(
        out,
        "  DFSPH divergence solve: %.2f iterations a substep (most %u), error %.3g 1/s mean (%.3g 1/s in the "
        "worst substep)\n",
        d.divergence_iterations / n, d.divergence_iterations_max, d.divergence_error_sum / n,
        static_cast<double>(d.divergence_error_max));
  std::fprintf(
      out,
      "  DFSPH solves stopped at their caps above their bounds: %llu density, %llu divergence (of %llu "
      "substeps); Chebyshev guard turned %llu to plain steps\n",
      static_cast<unsigned long long>(d.density_capped), static_cast<unsigned long long>(d.divergence_capped),
      static_cast<unsigned long long>(d.substeps), static_cast<unsigned long long>(d.guarded));
}

std::string RunStats::write_json(const std::string& path, const std::string& scene,
                                 const std::string& backend, double wall_s, const std::string& extra) const {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return std::strerror(errno);
  static const char* kStages[SPH_STAGE_COUNT] = {"hash_sort", "cell_ranges", "density", "forces",
                                                 "integrate", "collide",     "emit",    "other"};
  const double frames = frames_ > 0 ? frames_ : 1.0;
  std::string escaped;
  for (char c : scene) {
    if (c == '"' || c == '\\') escaped += '\\';
    escaped += c;
  }
  std::fprintf(f,
               "{\"benchmark\": \"sph-run\", \"scene\": \"%s\", \"backend\": \"%s\", \"frames\": %u, "
               "\"wall_s\": %.4f, \"s_per_frame\": %.6g, \"output_s_per_frame\": %.6g, \"substeps\": %llu, "
               "\"particles_end\": %u, \"particles_max\": %u, \"dt_min\": %.6g, \"dt_max\": %.6g, "
               "\"max_speed\": %.6g, \"neighbors_mean\": %.4f, \"memory_bytes\": %llu, \"stage_ms\": {",
               escaped.c_str(), backend.c_str(), frames_, wall_s, step_ms_ * 1e-3 / frames,
               output_ms_ * 1e-3 / (frames_ + 1.0), static_cast<unsigned long long>(substeps_),
               last_.particle_count, particles_max_, dt_min_, dt_max_, speed_max_, last_.neighbors_mean,
               static_cast<unsigned long long>(last_.memory_bytes));
  for (int i = 0; i < SPH_STAGE_COUNT; ++i)
    std::fprintf(f, "\"%s\": %.6g%s", kStages[i], stage_ms_[i], i + 1 < SPH_STAGE_COUNT ? ", " : "");
  std::fprintf(f, "}");
  if (solves_.substeps > 0) {  // DFSPH's solves (sph_stats' names, over the run)
    const Solves& d = solves_;
    const double n = static_cast<double>(d.substeps);
    std::fprintf(
        f,
        ", \"dfsph\": {\"substeps\": %llu, \"pressure_iterations\": %llu, \"pressure_iterations_max\": %u, "
        "\"density_error_mean\": %.6g, \"density_error_max\": %.6g, \"density_error_largest\": %.6g, "
        "\"divergence_iterations\": %llu, \"divergence_iterations_max\": %u, "
        "\"divergence_error_mean\": %.6g, \"divergence_error_max\": %.6g, "
        "\"pressure_solves_capped\": %llu, \"divergence_solves_capped\": %llu, "
        "\"pressure_solves_guarded\": %llu}",
        static_cast<unsigned long long>(d.substeps), static_cast<unsigned long long>(d.density_iterations),
        d.density_iterations_max, d.density_error_sum / n, static_cast<double>(d.density_error_max),
        static_cast<double>(d.density_error_largest),
        static_cast<unsigned long long>(d.divergence_iterations), d.divergence_iterations_max,
        d.divergence_error_sum / n, static_cast<double>(d.divergence_error_max),
        static_cast<unsigned long long>(d.density_capped),
        static_cast<unsigned long long>(d.divergence_capped), static_cast<unsigned long long>(d.guarded));
  }
  std::fprintf(f, "%s%s}\n", extra.empty() ? "" : ", ", extra.c_str());
  const bool failed = std::ferror(f) != 0;
  const int error = errno;
  if (std::fclose(f) != 0) return std::strerror(errno);
  return failed ? std::strerror(error) : "";
}

}  // namespace sph_tools
