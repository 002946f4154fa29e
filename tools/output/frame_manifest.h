// SPDX-License-Identifier: MIT
// The manifest: what a run committed to its output directory, "sph-run-manifest.jsonl"
// (docs/cli.md). JSON Lines: a header line, then for every frame a "writing" line before its
// files are moved into place and a "complete" line once all of them are; readers trust a
// frame only with its "complete" line (and ignore a last line without its newline: a write cut
// by a kill). A run's start replaces the manifest (so no earlier frame is trusted) and then
// removes the files the earlier run recorded, so the frames of an earlier, longer run do not
// linger beside the new ones; files no manifest recorded are never touched.
#ifndef SPH_TOOLS_FRAME_MANIFEST_H
#define SPH_TOOLS_FRAME_MANIFEST_H

#include <cstdint>
#include <string>
#include <vector>

#include "staging.h"

namespace sph_tools {

struct ManifestHeader {
  std::string scene;  // the scene file, as given
  float fps = 0.0f;
  uint32_t frames = 0;  // frames the run means to simulate (frame 0 and 1..frames are written)
};

class FrameManifest {
 public:
  // Replaces the manifest of `directory` (written in `staging`, then renamed into place) and
  // removes the outputs an earlier run's manifest recorded. Throws std::runtime_error.
  FrameManifest(const std::string& directory, const StagingDirectory& staging, const ManifestHeader& header);
  ~FrameManifest();
  FrameManifest(const FrameManifest&) = delete;
  FrameManifest& operator=(const FrameManifest&) = delete;

  // A frame's files (output names) are about to be moved into place / all are in place.
  void writing(uint32_t frame, double time, const std::vector<std::string>& files);
  void complete(uint32_t frame, double time, const std::vector<std::string>& files);
  // The scene objects' tables (loads, probes: written a line a frame, in place, not staged), as
  // soon as they are created, so that a later run removes them like frames.
  void tables(const std::vector<std::string>& names);
  // The preview video, likewise.
  void writing_video(const std::string& name);
  void complete_video(const std::string& name);
  // The run's last line: how it ended ("complete", "interrupted", "failed") and the last frame
  // written (frames 0..last_frame are complete).
  void end(const char* how, uint32_t last_frame);

  // How many outputs of an earlier run the constructor removed.
  int removed_earlier() const { return removed_earlier_; }

 private:
  void append(const std::string& line);

  std::string path_;
  int fd_ = -1;
  int removed_earlier_ = 0;
};

}  // namespace sph_tools

#endif
