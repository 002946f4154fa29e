// SPDX-License-Identifier: MIT
// sph-run's command line.
#ifndef SPH_TOOLS_CLI_OPTIONS_H
#define SPH_TOOLS_CLI_OPTIONS_H

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

struct CliOptions {
  std::string scene;
  std::optional<uint32_t> frames;
  sph_backend backend = SPH_BACKEND_AUTO;
  std::optional<std::string> out;
  std::optional<std::vector<OutputFormat>> formats;  // set and empty: "--format none"
  bool surface = false;
  bool preview = false;
  std::optional<bool> preview_surface;  // --preview-style: true for surface, false for particles
  uint32_t threads = 0;
  bool dfsph_lists = false;  // sph_context_def.cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS
  bool quiet = false;
  std::optional<std::string> stats_json;  // --stats-json FILE: the run's figures, machine-readable
  bool help = false;
  bool version = false;
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws UsageError naming the offending argument (and, for an unknown option, the nearest
// known one).
CliOptions parse_cli(int argc, char** argv);
const char* usage_text();

}  // namespace sph_tools

#endif
