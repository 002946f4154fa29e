// SPDX-License-Identifier: MIT
#include "frame_writer.h"

#include <chrono>
#include <cstdio>

#include "new_file.h"
#include "staging.h"
#include "video.h"
#include "writers.h"

namespace sph_tools {

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// A frame's files in the staging directory: removed unless committed.
class StagedFrame {
 public:
  explicit StagedFrame(const StagingDirectory& staging) : staging_(staging) {}
  ~StagedFrame() {
    for (const std::string& name : names_) staging_.discard(name);
  }
  StagedFrame(const StagedFrame&) = delete;
  StagedFrame& operator=(const StagedFrame&) = delete;
  // Registers an output and returns its staged path.
  std::string add(const std::string& name) {
    names_.push_back(name);
    return staging_.file(name);
  }
  const std::vector<std::string>& names() const { return names_; }
  // Moves every staged file into the output directory, between the manifest's two lines.
  void commit(FrameManifest& manifest, uint32_t frame, double time) {
    manifest.writing(frame, time, names_);
    for (const std::string& name : names_) staging_.commit(name);
    const std::vector<std::string> committed = std::move(names_);
    names_.clear();
    manifest.complete(frame, time, committed);
  }

 private:
  const StagingDirectory& staging_;
  std::vector<std::string> names_;
};

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
    case OutputFormat::kVtp:
      return "vtp";
    default:
      return "csv";
  }
}

FrameWriter::FrameWriter(const FrameWriterOptions& options, const SceneRuntime& runtime,
                         const ManifestHeader& header)
    : options_(options) {
  make_directories(options_.directory);
  remove_stale_temporaries(options_.directory);
  staging_ = std::make_unique<StagingDirectory>(options_.directory);
  manifest_ = std::make_unique<FrameManifest>(options_.directory, *staging_, header);
  if (options_.preview) preview_ = std::make_unique<PreviewRenderer>(runtime);
}

std::string FrameWriter::name(const char* prefix, uint32_t frame, const char* extension) {
  char text[64];
  std::snprintf(text, sizeof text, "%s_%04u.%s", prefix, frame, extension);
  return text;
}

std::string FrameWriter::path(const char* prefix, uint32_t frame, const char* extension) const {
  return options_.directory + "/" + name(prefix, frame, extension);
}

void FrameWriter::write(const SceneRuntime& runtime, const ParticleFrame& frame) {
  StagedFrame staged(*staging_);
  times_ = FrameWriteTimes{};
  std::vector<SeriesEntry> series = vtp_series_;  // kept only if the frame is committed
  auto start = std::chrono::steady_clock::now();
  for (OutputFormat format : options_.formats) {
    const std::string file = staged.add(name("fluid", frame.frame, format_extension(format)));
    switch (format) {
      case OutputFormat::kCsv:
        write_csv(frame, file);
        break;
      case OutputFormat::kPly:
        write_ply(frame, file);
        break;
      case OutputFormat::kVtp:
        write_vtp(frame, file);
        // The series so far, this frame included, committed with the frame.
        series.push_back({name("fluid", frame.frame, "vtp"), frame.time});
        write_pvd(series, staged.add(kSeriesName));
        break;
      case OutputFormat::kVdb:
#ifdef SPH_TOOLS_HAVE_OPENVDB
        write_vdb_points(frame, file);
#endif
        break;
    }
  }
  times_.particles_ms = ms_since(start);
  start = std::chrono::steady_clock::now();
  if (options_.surface) {
#ifdef SPH_TOOLS_HAVE_OPENVDB
    const std::string vdb = staged.add(name("surface", frame.frame, "vdb"));
    const std::string obj = staged.add(name("surface", frame.frame, "obj"));
    write_surface(frame, options_.surface_radius, options_.surface_voxel, vdb, obj, &mesh_);
#endif
  }
  times_.surface_ms = ms_since(start);
  start = std::chrono::steady_clock::now();
  if (preview_) {
    const bool draw_surface = options_.surface && options_.preview_surface;
    preview_->render(runtime, frame.position.data(), frame.velocity.data(), frame.count,
                     draw_surface ? &mesh_ : nullptr, frame.frame, frame.time, &image_);
    NewFile png(staged.add(name("preview", frame.frame, "png")));
    write_png(image_, png.get(), png.path());
    png.close();
  }
  times_.preview_ms = ms_since(start);
  staged.commit(*manifest_, frame.frame, frame.time);
  vtp_series_ = std::move(series);
}

std::string FrameWriter::write_preview_video(float fps) {
  const std::string video = "preview.mp4";
  const std::string problem =
      encode_mp4(options_.directory + "/preview_%04d.png", 0, fps, staging_->file(video));
  if (!problem.empty()) {
    staging_->discard(video);
    return problem;
  }
  manifest_->writing_video(video);
  staging_->commit(video);
  manifest_->complete_video(video);
  return "";
}

}  // namespace sph_tools
