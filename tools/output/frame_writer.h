// SPDX-License-Identifier: MIT
// FrameWriter: every file of one frame (particles in the chosen formats, the surface, the
// preview image), written in the run's private staging directory, then moved into the output
// directory between a "writing" and a "complete" line of the run's manifest, which is what
// makes a frame a unit for readers (docs/cli.md, "Output files").
#ifndef SPH_TOOLS_FRAME_WRITER_H
#define SPH_TOOLS_FRAME_WRITER_H

#include <memory>
#include <string>
#include <vector>

#include "frame_manifest.h"
#include "particle_frame.h"
#include "preview_renderer.h"
#include "scene_desc.h"
#include "scene_runtime.h"
#include "surface_mesh.h"
#include "writers.h"

namespace sph_tools {

// Whether this build can write a format (vdb needs OpenVDB), and surfaces.
bool format_available(OutputFormat format);
bool surface_available();
const char* format_extension(OutputFormat format);

struct FrameWriterOptions {
  std::string directory;
  std::vector<OutputFormat> formats;  // may be empty: particles are not written
  bool surface = false;
  bool preview = false;
  bool preview_surface = false;  // draw the surface instead of the particles
  float surface_radius = 0.0f;   // m
  float surface_voxel = 0.0f;    // m
};

// Wall time of the last frame's output, by kind, in milliseconds.
struct FrameWriteTimes {
  double particles_ms = 0.0, surface_ms = 0.0, preview_ms = 0.0;
};

class FrameWriter {
 public:
  // Creates the directory, removes what killed runs left there, and starts the manifest (which
  // removes an earlier run's outputs). Throws std::runtime_error.
  FrameWriter(const FrameWriterOptions& options, const SceneRuntime& runtime, const ManifestHeader& header);
  // Writes the frame's files; throws std::runtime_error (a frame without its "complete" line
  // in the manifest is not one; its staged files are removed).
  void write(const SceneRuntime& runtime, const ParticleFrame& frame);
  // Encodes the committed preview PNGs into preview.mp4 through ffmpeg (staged, then moved in).
  // Returns "" on success, else what went wrong.
  std::string write_preview_video(float fps);
  // The scene objects' tables, recorded in the manifest (FrameManifest::tables).
  void record_tables(const std::vector<std::string>& names) { manifest_->tables(names); }
  // The manifest's last line (FrameManifest::end).
  void end(const char* how, uint32_t last_frame) { manifest_->end(how, last_frame); }
  const FrameWriteTimes& times() const { return times_; }
  // The file of a frame: "DIR/fluid_0012.ply", "DIR/preview_0012.png", ...
  std::string path(const char* prefix, uint32_t frame, const char* extension) const;
  // Its name alone: "fluid_0012.ply".
  static std::string name(const char* prefix, uint32_t frame, const char* extension);
  const FrameWriterOptions& options() const { return options_; }

 private:
  FrameWriterOptions options_;
  std::unique_ptr<StagingDirectory> staging_;
  std::unique_ptr<FrameManifest> manifest_;
  std::unique_ptr<PreviewRenderer> preview_;
  SurfaceMesh mesh_;
  Image image_;
  FrameWriteTimes times_;
  std::vector<SeriesEntry> vtp_series_;  // the committed .vtp frames, for fluid.pvd
};

}  // namespace sph_tools

#endif
