// SPDX-License-Identifier: MIT
#include "staging.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace sph_tools {

namespace {

constexpr char kStagingPrefix[] = ".sph-run-";
constexpr size_t kStagingPrefixLength = sizeof kStagingPrefix - 1;

bool digits(const std::string& s, size_t from, size_t to) {
  if (to - from < 4) return false;
  for (size_t i = from; i < to; ++i)
    if (s[i] < '0' || s[i] > '9') return false;
  return true;
}

bool is_staging_name(const std::string& name) {
  if (name.size() != kStagingPrefixLength + 6 || name.compare(0, kStagingPrefixLength, kStagingPrefix) != 0)
    return false;
  for (size_t i = kStagingPrefixLength; i < name.size(); ++i) {
    const char c = name[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))) return false;
  }
  return true;
}

// Removes sph-run's own names in `dir`, then `dir` itself if that emptied it.
bool empty_and_remove(const std::string& dir) {
  DIR* listing = opendir(dir.c_str());
  if (!listing) return false;
  std::vector<std::string> names;
  while (const dirent* entry = readdir(listing)) names.push_back(entry->d_name);
  closedir(listing);
  for (const std::string& name : names) {
    // An encoder's partial output (".preview.mp4.tmp") is ours too.
    const bool ours = is_output_name(name) || name == kManifestName ||
                      (name.size() > 5 && name[0] == '.' && name.compare(name.size() - 4, 4, ".tmp") == 0 &&
                       is_output_name(name.substr(1, name.size() - 5)));
    if (ours) ::unlink((dir + "/" + name).c_str());
  }
  return ::rmdir(dir.c_str()) == 0;
}

// A character of an object's name that its table's file name keeps (any other becomes '_').
bool kept_in_table_name(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '-';
}

}  // namespace

std::string object_table_name(const char* prefix, size_t index, const std::string& name) {
  std::string file = std::string(prefix) + "_" + std::to_string(index);
  if (!name.empty()) file += "_";
  for (size_t i = 0; i < name.size() && i < kMaxTableNameChars; ++i)
    file += kept_in_table_name(name[i]) ? name[i] : '_';
  return file + ".csv";
}

namespace {

// object_table_name's names, and nothing else.
bool is_table_name(const std::string& name) {
  static const char* const prefixes[] = {"loads_", "probe_"};
  const size_t suffix = 4;  // ".csv"
  if (name.size() <= suffix || name.compare(name.size() - suffix, suffix, ".csv") != 0) return false;
  const size_t end = name.size() - suffix;
  for (const char* prefix : prefixes) {
    const size_t p = std::strlen(prefix);
    if (name.compare(0, p, prefix) != 0) continue;
    size_t i = p;
    while (i < end && name[i] >= '0' && name[i] <= '9') ++i;
    if (i == p) return false;  // no index
    if (i == end) return true;
    if (name[i] != '_' || end - (i + 1) > kMaxTableNameChars || i + 1 == end) return false;
    for (size_t k = i + 1; k < end; ++k)
      if (!kept_in_table_name(name[k]) && name[k] != '_') return false;
    return true;
  }
  return false;
}

}  // namespace

bool is_output_name(const std::string& name) {
  if (name == "preview.mp4" || name == kSeriesName || is_table_name(name)) return true;
  struct Kind {
    const char* prefix;
    std::vector<const char*> extensions;
  };
  static const Kind kinds[] = {
      {"fluid_", {".vdb", ".ply", ".csv", ".vtp"}}, {"surface_", {".vdb", ".obj"}}, {"preview_", {".png"}}};
  for (const Kind& kind : kinds) {
    const size_t p = std::strlen(kind.prefix);
    if (name.compare(0, p, kind.prefix) != 0) continue;
    for (const char* extension : kind.extensions) {
      const size_t e = std::strlen(extension);
      if (name.size() > p + e && name.compare(name.size() - e, e, extension) == 0 &&
          digits(name, p, name.size() - e))
        return true;
    }
  }
  return false;
}

StagingDirectory::StagingDirectory(const std::string& output_directory) : output_(output_directory) {
  std::string pattern = output_directory + "/" + kStagingPrefix + "XXXXXX";
  if (!::mkdtemp(&pattern[0]))
    throw std::runtime_error("cannot create a staging directory in " + output_directory + ": " +
                             std::strerror(errno));
  path_ = pattern;
  // The lock tells remove_stale_temporaries of another run that this directory is alive.
  lock_fd_ = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    if (lock_fd_ >= 0) ::close(lock_fd_);
    ::rmdir(path_.c_str());
    throw std::runtime_error("cannot lock the staging directory " + path_ + ": " + std::strerror(error));
  }
}

StagingDirectory::~StagingDirectory() {
  empty_and_remove(path_);
  ::close(lock_fd_);
}

void StagingDirectory::commit(const std::string& name) const {
  const std::string from = file(name), to = output_ + "/" + name;
  if (std::rename(from.c_str(), to.c_str()) != 0)
    throw std::runtime_error("cannot move " + from + " to " + to + ": " + std::strerror(errno));
}

void StagingDirectory::discard(const std::string& name) const { ::unlink(file(name).c_str()); }

int remove_stale_temporaries(const std::string& directory) {
  DIR* listing = opendir(directory.c_str());
  if (!listing) return 0;
  std::vector<std::string> names;
  while (const dirent* entry = readdir(listing)) names.push_back(entry->d_name);
  closedir(listing);
  int removed = 0;
  for (const std::string& name : names) {
    const std::string path = directory + "/" + name;
    struct stat st;
    if (::lstat(path.c_str(), &st) != 0 || st.st_uid != ::geteuid()) continue;
    if (is_staging_name(name) && S_ISDIR(st.st_mode)) {
      const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
      if (fd < 0) continue;
      // A live run holds the lock; a killed one's was released with its process.
      if (::flock(fd, LOCK_EX | LOCK_NB) == 0 && empty_and_remove(path)) ++removed;
      ::close(fd);
    } else if (S_ISREG(st.st_mode) && name.size() > 5 && name[0] == '.' &&
               name.compare(name.size() - 4, 4, ".tmp") == 0 &&
               is_output_name(name.substr(1, name.size() - 5))) {
      removed += ::unlink(path.c_str()) == 0 ? 1 : 0;
    }
  }
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

}  // namespace sph_tools
