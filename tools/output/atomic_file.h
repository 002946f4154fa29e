// Files of a frame are written under temporary names and renamed into place together once
// all of them are complete, so an interrupted run leaves only whole frames behind.
#ifndef SPH_TOOLS_ATOMIC_FILE_H
#define SPH_TOOLS_ATOMIC_FILE_H

#include <string>
#include <utility>
#include <vector>

namespace sph_tools {

// The temporary name of `final_path`: a hidden file in the same directory
// ("out/.fluid_0001.ply.tmp"), so the rename stays within one file system.
std::string temporary_name(const std::string& final_path);

// Removes temporary files a killed run left in `directory` (".*.tmp"). Returns how many.
int remove_stale_temporaries(const std::string& directory);

// Creates a directory and its parents; throws std::runtime_error on failure.
void make_directories(const std::string& path);

class FrameCommit {
 public:
  FrameCommit() = default;
  FrameCommit(const FrameCommit&) = delete;
  FrameCommit& operator=(const FrameCommit&) = delete;
  ~FrameCommit();  // removes the temporaries of an uncommitted frame

  // Registers a file and returns the temporary name to write it under.
  std::string add(const std::string& final_path);
  // Renames every temporary to its final name; throws std::runtime_error on failure.
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> files_;  // temporary, final
};

}  // namespace sph_tools

#endif
