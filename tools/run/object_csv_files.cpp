// SPDX-License-Identifier: MIT
#include "object_csv_files.h"

#include <cctype>
#include <cerrno>
#include <cstring>

namespace sph_tools {

std::string ObjectCsvFiles::open(const std::string& directory, const char* prefix, size_t index,
                                 const std::string& name, const char* header) {
  std::string path = directory + "/" + prefix + "_" + std::to_string(index);
  if (!name.empty()) path += "_";
  for (char ch : name) path += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-') ? ch : '_';
  path += ".csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return path + ": " + std::strerror(errno);
  files_.push_back(File{index, path, f});
  std::fputs(header, f);
  return "";
}

std::string ObjectCsvFiles::close() {
  std::string problem;
  for (File& f : files_)
    if (f.file && std::fclose(f.file) != 0 && problem.empty()) problem = f.path + ": " + std::strerror(errno);
  files_.clear();
  return problem;
}

}  // namespace sph_tools
