// SPDX-License-Identifier: MIT
// The CSV files sph-run writes one per scene object (collider loads, probes):
// <output>/<prefix>_<index>[_<name>].csv (object_table_name, docs/cli.md).
#ifndef SPH_TOOLS_RUN_OBJECT_CSV_FILES_H
#define SPH_TOOLS_RUN_OBJECT_CSV_FILES_H

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace sph_tools {

class ObjectCsvFiles {
 public:
  struct File {
    size_t object;     // the object's index in the scene
    std::string name;  // the file's name (object_table_name)
    std::string path;
    std::FILE* file;
  };

  // Opens (truncates) object `index`'s file and writes `header` (a line with its newline).
  // Returns "" or what went wrong.
  std::string open(const std::string& directory, const char* prefix, size_t index, const std::string& name,
                   const char* header);
  // Closes every file (also on destruction). Returns "" or the first thing that went wrong.
  std::string close();
  ~ObjectCsvFiles() { close(); }

  const std::vector<File>& files() const { return files_; }
  // The names of the files open now.
  std::vector<std::string> names() const;

 private:
  std::vector<File> files_;
};

}  // namespace sph_tools

#endif
