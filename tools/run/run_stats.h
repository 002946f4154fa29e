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
  // DFSPH's solves over the run, three lines (print() includes them); nothing for a world without.
  void print_solves(std::FILE* out) const;
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
  // DFSPH's solves over the run (sph_stats' solve fields, frame by frame); a WCSPH world leaves
  // them zero (a DFSPH substep runs at least two density iterations), and the summary leaves them out.
  struct Solves {
    uint64_t density_iterations = 0, divergence_iterations = 0;
    uint32_t density_iterations_max = 0, divergence_iterations_max = 0;
    double density_error_sum = 0.0, divergence_error_sum = 0.0;  // each frame's mean x its substeps
    float density_error_max = 0.0f, divergence_error_max = 0.0f, density_error_largest = 0.0f;
    uint64_t density_capped = 0, divergence_capped = 0, guarded = 0;
    uint64_t substeps = 0;  // of the frames that ran a solve
  };
  Solves solves_;
};

}  // namespace sph_tools

#endif
