#include "atomic_file.h"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace sph_tools {

std::string temporary_name(const std::string& final_path) {
  const size_t slash = final_path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : final_path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? final_path : final_path.substr(slash + 1);
  return dir + "." + name + ".tmp";
}

int remove_stale_temporaries(const std::string& directory) {
  DIR* dir = opendir(directory.c_str());
  if (!dir) return 0;
  int removed = 0;
  while (const dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    if (name.size() > 5 && name[0] == '.' && name.compare(name.size() - 4, 4, ".tmp") == 0)
      removed += std::remove((directory + "/" + name).c_str()) == 0 ? 1 : 0;
  }
  closedir(dir);
  return removed;
}

void make_directories(const std::string& path) {
  std::string partial;
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    partial = path.substr(0, pos);
    if (partial.empty()) continue;
    if (mkdir(partial.c_str(), 0755) != 0 && errno != EEXIST)
      throw std::runtime_error("cannot create directory " + partial + ": " + std::strerror(errno));
  }
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw std::runtime_error("cannot create directory " + path + ": a file of that name exists");
}

FrameCommit::~FrameCommit() {
  for (const auto& f : files_) std::remove(f.first.c_str());
}

std::string FrameCommit::add(const std::string& final_path) {
  files_.emplace_back(temporary_name(final_path), final_path);
  return files_.back().first;
}

void FrameCommit::commit() {
  for (const auto& f : files_)
    if (std::rename(f.first.c_str(), f.second.c_str()) != 0)
      throw std::runtime_error("cannot rename " + f.first + " to " + f.second + ": " + std::strerror(errno));
  files_.clear();
}

}  // namespace sph_tools
