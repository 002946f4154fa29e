// SPDX-License-Identifier: MIT
#include "object_csv_files.h"

#include <cerrno>
#include <cstring>

#include "staging.h"

namespace sph_tools {

std::string ObjectCsvFiles::open(const std::string& directory, const char* prefix, size_t index,
                                 const std::string& name, const char* header) {
  const std::string file_name = object_table_name(prefix, index, name);
  const std::string path = directory + "/" + file_name;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return path + ": " + std::strerror(errno);
  files_.push_back(File{index, file_name, path, f});
  std::fputs(header, f);
  return "";
}

std::vector<std::string> ObjectCsvFiles::names() const {
  std::vector<std::string> out;
  for (const File& f : files_) out.push_back(f.name);
  return out;
}

std::string ObjectCsvFiles::close() {
  std::string problem;
  for (File& f : files_)
    if (f.file && std::fclose(f.file) != 0 && problem.empty()) problem = f.path + ": " + std::strerror(errno);
  files_.clear();
  return problem;
}

}  // namespace sph_tools
