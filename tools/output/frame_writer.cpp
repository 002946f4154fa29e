#include "frame_writer.h"

#include <chrono>
#include <cstdio>

#include "atomic_file.h"
#include "writers.h"

namespace sph_tools {

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

bool format_available(OutputFormat format) {
#ifdef SPH_TOOLS_HAVE_OPENVDB
  (void)format;
  return true;
#else
  return format != OutputFormat::kVdb;
#endif
}

bool surface_available() {
#ifdef SPH_TOOLS_HAVE_OPENVDB
  return true;
#else
  return false;
#endif
}

const char* format_extension(OutputFormat format) {
  switch (format) {
    case OutputFormat::kVdb:
      return "vdb";
    case OutputFormat::kPly:
      return "ply";
    default:
      return "csv";
  }
}

FrameWriter::FrameWriter(const FrameWriterOptions& options, const SceneRuntime& runtime) : options_(options) {
  make_directories(options_.directory);
  remove_stale_temporaries(options_.directory);
  if (options_.preview) preview_ = std::make_unique<PreviewRenderer>(runtime);
}

std::string FrameWriter::path(const char* prefix, uint32_t frame, const char* extension) const {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%04u.%s", prefix, frame, extension);
  return options_.directory + "/" + name;
}

void FrameWriter::write(const SceneRuntime& runtime, const ParticleFrame& frame) {
  FrameCommit commit;
  times_ = FrameWriteTimes{};
  auto start = std::chrono::steady_clock::now();
  for (OutputFormat format : options_.formats) {
    const std::string temp = commit.add(path("fluid", frame.frame, format_extension(format)));
    switch (format) {
      case OutputFormat::kCsv:
        write_csv(frame, temp);
        break;
      case OutputFormat::kPly:
        write_ply(frame, temp);
        break;
      case OutputFormat::kVdb:
#ifdef SPH_TOOLS_HAVE_OPENVDB
        write_vdb_points(frame, temp);
#endif
        break;
    }
  }
  times_.particles_ms = ms_since(start);
  start = std::chrono::steady_clock::now();
  if (options_.surface) {
#ifdef SPH_TOOLS_HAVE_OPENVDB
    const std::string vdb = commit.add(path("surface", frame.frame, "vdb"));
    const std::string obj = commit.add(path("surface", frame.frame, "obj"));
    write_surface(frame, options_.surface_radius, options_.surface_voxel, vdb, obj, &mesh_);
#endif
  }
  times_.surface_ms = ms_since(start);
  start = std::chrono::steady_clock::now();
  if (preview_) {
    const bool draw_surface = options_.surface && options_.preview_surface;
    preview_->render(runtime, frame.position.data(), frame.velocity.data(), frame.count,
                     draw_surface ? &mesh_ : nullptr, &image_);
    write_png(image_, commit.add(path("preview", frame.frame, "png")));
  }
  times_.preview_ms = ms_since(start);
  commit.commit();
}

}  // namespace sph_tools
