// SPDX-License-Identifier: MIT
// What a run did, gathered frame by frame from sph_stats and printed when it ends.
#ifndef SPH_TOOLS_RUN_STATS_H
#define SPH_TOOLS_RUN_STATS_H

#include <cstdint>
#include <cstdio>
#include <string>

#include "sph_c.h"

namespace sph_tools {

class RunStats {
 public:
  void add_frame(const sph_stats& stats, double step_wall_ms, double output_wall_ms);
  void add_output(double output_wall_ms) { output_ms_ += output_wall_ms; }
  // The output's share by kind (particles, surface, preview), in ms.
  void add_output_kinds(double particles_ms, double surface_ms, double preview_ms) {
    particles_ms_ += particles_ms;
    surface_ms_ += surface_ms;
    preview_ms_ += preview_ms;
  }
  // Prints the summary. `what` heads it ("dam_break.json: 120 frames").
  void print(std::FILE* out, const std::string& what, const std::string& backend, double wall_s) const;
  uint32_t frames() const { return frames_; }
  uint64_t substeps() const { return substeps_; }
  // Writes the same figures as print() as one JSON object; returns "" or why the file could not
  // be written. `extra`: more members ("\"ranks\": 2"), written after sph-run's.
  std::string write_json(const std::string& path, const std::string& scene, const std::string& backend,
                         double wall_s, const std::string& extra = "") const;

 private:
  uint32_t frames_ = 0;
  uint64_t substeps_ = 0;
  uint32_t particles_max_ = 0;
  double step_ms_ = 0.0, output_ms_ = 0.0, particles_ms_ = 0.0, surface_ms_ = 0.0, preview_ms_ = 0.0;
  float dt_min_ = 0.0f, dt_max_ = 0.0f, speed_max_ = 0.0f;
  double stage_ms_[SPH_STAGE_COUNT] = {};
  sph_stats last_{};
};

}  // namespace sph_tools

#endif
