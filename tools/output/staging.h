// SPDX-License-Identifier: MIT
// Where a frame's files are written before they are committed: a private directory inside the
// output directory, made by mkdtemp (".sph-run-XXXXXX": an unpredictable name, created
// exclusively with mode 0700, so nobody else can plant a file or a link in it), locked with
// flock while the run lives, and removed when the run ends. Files move from it into the output
// directory by rename(2), which replaces a link at the target instead of writing through it.
#ifndef SPH_TOOLS_STAGING_H
#define SPH_TOOLS_STAGING_H

#include <string>

namespace sph_tools {

// Whether `name` is one of sph-run's own output file names: "fluid_NNNN.vdb|ply|csv",
// "surface_NNNN.vdb|obj", "preview_NNNN.png" (at least four digits), "fluid_NNNN.vtp", "fluid.pvd",
// "preview.mp4", or a scene object's table (object_table_name). Nothing else in an output directory
// is ever removed or replaced by sph-run but its manifest.
bool is_output_name(const std::string& name);

// The most characters of an object's name that go into its table's file name: with the prefix and
// the index the name stays below the 255 bytes a file name may have.
constexpr size_t kMaxTableNameChars = 200;
// The file name of scene object `index`'s table ("loads" or "probe"): "<prefix>_<index>.csv", or
// "<prefix>_<index>_<name>.csv" with the name's characters other than letters, digits and '-' as
// '_', its first kMaxTableNameChars (docs/cli.md).
std::string object_table_name(const char* prefix, size_t index, const std::string& name);

// The manifest of the run that last wrote to an output directory (frame_manifest.h).
constexpr const char* kManifestName = "sph-run-manifest.jsonl";
// The ParaView time series of the .vtp frames, rewritten with each frame.
constexpr const char* kSeriesName = "fluid.pvd";

class StagingDirectory {
 public:
  // Creates the directory inside `output_directory` (which must exist); throws
  // std::runtime_error.
  explicit StagingDirectory(const std::string& output_directory);
  ~StagingDirectory();  // removes the files left in it (sph-run's names only) and it
  StagingDirectory(const StagingDirectory&) = delete;
  StagingDirectory& operator=(const StagingDirectory&) = delete;

  // The staged path of an output file.
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // Moves the staged `name` to the output directory (replacing a file of that name there);
  // throws std::runtime_error.
  void commit(const std::string& name) const;
  // Removes the staged `name` if it is there.
  void discard(const std::string& name) const;

 private:
  std::string output_;
  std::string path_;
  int lock_fd_ = -1;
};

// Removes what runs that were killed left in `directory`: staging directories (".sph-run-"
// and six characters) that are real directories (never through a link) owned by this user and
// not locked by a live run, with only sph-run's own file names in them removed (a directory is
// removed only when that empties it); and the hidden temporaries of earlier sph-run versions
// (".fluid_0001.ply.tmp": a dot, an output name, ".tmp"), regular files owned by this user.
// Anything else, hidden ".tmp" files of other programs included, stays. Returns how many
// entries were removed.
int remove_stale_temporaries(const std::string& directory);

// Creates a directory and its parents; throws std::runtime_error on failure.
void make_directories(const std::string& path);

}  // namespace sph_tools

#endif
