// SPDX-License-Identifier: MIT
// NewFile: a file that must not exist yet, for one of a frame's outputs. Created with
// O_CREAT | O_EXCL | O_NOFOLLOW, so it is never an existing file nor the target of a link that
// someone planted, and closed with its write errors reported (a full disk, or a file size
// limit: sph-run ignores SIGXFSZ, so such a write fails with EFBIG instead of killing it).
#ifndef SPH_TOOLS_NEW_FILE_H
#define SPH_TOOLS_NEW_FILE_H

#include <cstdio>
#include <string>

namespace sph_tools {

class NewFile {
 public:
  // Throws std::runtime_error naming the path and the reason.
  explicit NewFile(const std::string& path);
  ~NewFile();  // closes a file close() was not called for (its errors are then lost)
  NewFile(const NewFile&) = delete;
  NewFile& operator=(const NewFile&) = delete;

  std::FILE* get() const { return file_; }
  const std::string& path() const { return path_; }
  // Flushes and closes; throws std::runtime_error if any write or the close failed.
  void close();

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

// Creates `path` as an empty new file (as NewFile does) and closes it: for writers that open
// files by name themselves (OpenVDB), so the name is still claimed exclusively.
void create_new_file(const std::string& path);

}  // namespace sph_tools

#endif
