// SPDX-License-Identifier: MIT
// The colliders' loads as CSV files, one per collider that asks for them in the scene file
// ("loads": {...}): <output>/loads_<index>[_<name>].csv, a row per frame (docs/cli.md).
#ifndef SPH_TOOLS_RUN_LOAD_CSV_H
#define SPH_TOOLS_RUN_LOAD_CSV_H

#include <cstdint>
#include <string>
#include <vector>

#include "object_csv_files.h"
#include "scene_runtime.h"

namespace sph_tools {

class LoadCsv {
 public:
  // Opens (truncates) the files and writes their headers. Returns "" or what went wrong.
  std::string open(const std::string& directory, const SceneRuntime& runtime);
  // Appends frame `frame` (time in s) of every file. Returns "" or what went wrong.
  std::string write(const SceneRuntime& runtime, uint32_t frame, double time);
  // Closes the files (also on destruction). Returns "" or what went wrong.
  std::string close() { return files_.close(); }
  // The names of its files (the manifest records them).
  std::vector<std::string> names() const { return files_.names(); }

 private:
  ObjectCsvFiles files_;
};

}  // namespace sph_tools

#endif
