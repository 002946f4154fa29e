// FrameWriter: every file of one frame (particles in the chosen formats, the surface, the
// preview image), written under temporary names and renamed into place together.
#ifndef SPH_TOOLS_FRAME_WRITER_H
#define SPH_TOOLS_FRAME_WRITER_H

#include <memory>
#include <string>
#include <vector>

#include "particle_frame.h"
#include "preview_renderer.h"
#include "scene_desc.h"
#include "scene_runtime.h"
#include "surface_mesh.h"

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
  // Creates the directory (throws std::runtime_error) and removes temporaries a killed run left.
  FrameWriter(const FrameWriterOptions& options, const SceneRuntime& runtime);
  // Writes the frame's files; throws std::runtime_error (nothing of the frame stays behind).
  void write(const SceneRuntime& runtime, const ParticleFrame& frame);
  const FrameWriteTimes& times() const { return times_; }
  // The file of a frame: "DIR/fluid_0012.ply", "DIR/preview_0012.png", ...
  std::string path(const char* prefix, uint32_t frame, const char* extension) const;
  const FrameWriterOptions& options() const { return options_; }

 private:
  FrameWriterOptions options_;
  std::unique_ptr<PreviewRenderer> preview_;
  SurfaceMesh mesh_;
  Image image_;
  FrameWriteTimes times_;
};

}  // namespace sph_tools

#endif
