// sph-run: runs a scene file and writes its frames (docs/cli.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "cli_options.h"
#include "exit_codes.h"
#include "frame_writer.h"
#include "interrupt.h"
#include "library_error.h"
#include "particle_frame.h"
#include "progress.h"
#include "run_stats.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "scene_runtime.h"
#include "sph_c.h"
#include "video.h"

namespace sph_tools {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string file_stem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

struct Sink {
  sph_context* context = nullptr;
  ~Sink() { sph_context_destroy(context); }
};

int fail(int code, const std::string& message) {
  std::fprintf(stderr, "sph-run: %s\n", message.c_str());
  return code;
}

int run(int argc, char** argv) {
  CliOptions cli;
  try {
    cli = parse_cli(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "sph-run: %s\n\n%s", e.what(), usage_text());
    return kExitUsage;
  }
  if (cli.help) {
    std::fputs(usage_text(), stdout);
    return kExitOk;
  }
  if (cli.version) {
    std::printf("sph-run, %s\n", sph_get_build_info());
    std::printf("outputs: csv, ply%s%s\n", format_available(OutputFormat::kVdb) ? ", vdb" : "",
                surface_available() ? ", surfaces (vdb + obj)" : "");
    return kExitOk;
  }

  // ---- the scene file and the options that override it -----------------------------------
  SceneDesc scene;
  try {
    scene = load_scene_file(cli.scene);
  } catch (const SceneError& e) {
    return fail(kExitScene, cli.scene + ": " + e.what());
  }
  if (cli.frames) scene.frames = *cli.frames;
  FrameWriterOptions out;
  out.directory = cli.out                           ? *cli.out
                  : !scene.output.directory.empty() ? scene.output.directory
                                                    : "out/" + file_stem(cli.scene);
  if (cli.formats) {
    out.formats = *cli.formats;
  } else if (!scene.output.formats.empty()) {
    out.formats = scene.output.formats;
  } else {
    out.formats = {format_available(OutputFormat::kVdb) ? OutputFormat::kVdb : OutputFormat::kPly};
  }
  for (OutputFormat f : out.formats)
    if (!format_available(f))
      return fail(kExitUnavailable, std::string("--format ") + format_extension(f) +
                                        ": this build has no OpenVDB; use ply or csv (" +
                                        (cli.formats ? "from the command line" : "from output.format") + ")");
  out.surface = cli.surface || scene.output.surface;
  if (out.surface && !surface_available())
    return fail(kExitUnavailable, std::string(cli.surface ? "--surface" : "output.surface") +
                                      ": surfaces need OpenVDB, which this build lacks");
  out.preview = cli.preview || scene.output.preview;
  out.preview_surface = scene.output.preview_surface;
  const float spacing = scene.world.particle_spacing;
  out.surface_radius = scene.output.surface_radius > 0.0f ? scene.output.surface_radius : spacing;
  out.surface_voxel = scene.output.surface_voxel > 0.0f ? scene.output.surface_voxel : 0.5f * spacing;
  if (out.surface && out.surface_radius < 1.5f * out.surface_voxel)
    return fail(kExitScene, cli.scene + ": output.surface.particle_radius: expected at least 1.5 voxels (" +
                                std::to_string(1.5f * out.surface_voxel) + " m)");

  // ---- the backend and the world ---------------------------------------------------------------
  Sink owner;
  sph_context_def context_def;
  sph_context_def_init(&context_def);
  context_def.backend = cli.backend;
  context_def.cpu_worker_count = cli.threads;
  sph_result r = sph_context_create(&context_def, &owner.context);
  if (r == SPH_ERROR_UNSUPPORTED)
    return fail(kExitBackend, std::string("the ") + (cli.backend == SPH_BACKEND_CUDA ? "CUDA" : "requested") +
                                  " backend is not available: " + sph_get_last_error() +
                                  "\n  (use --backend cpu, or auto to take a GPU only when there is one)");
  if (r < 0) return fail(kExitRuntime, LibraryError(r, "creating the context").what());
  sph_backend used = SPH_BACKEND_CPU;
  sph_context_get_backend(owner.context, &used);
  const std::string backend_name = used == SPH_BACKEND_CUDA ? "CUDA" : "CPU";

  const bool tty = isatty(STDERR_FILENO) != 0;
  try {
    SceneRuntime runtime(scene, owner.context);
    FrameWriter writer(out, runtime);
    if (!cli.quiet) {
      std::string formats;
      for (OutputFormat f : out.formats)
        formats += std::string(formats.empty() ? "" : ",") + format_extension(f);
      std::fprintf(stderr, "sph-run: %s: %u frames at %g fps on the %s backend -> %s/ (%s%s%s)\n",
                   cli.scene.c_str(), scene.frames, static_cast<double>(scene.fps), backend_name.c_str(),
                   out.directory.c_str(), formats.empty() ? "no particles" : formats.c_str(),
                   out.surface ? ", surface" : "", out.preview ? ", preview" : "");
    }
    install_interrupt_handlers();
    Progress progress(scene.frames, tty, cli.quiet);
    RunStats stats;
    ParticleFrame frame;
    const Clock::time_point run_start = Clock::now();

    Clock::time_point t = Clock::now();
    read_particles(runtime.world(), 0, 0.0, &frame);
    writer.write(runtime, frame);
    stats.add_output(ms_since(t));
    uint32_t written = 1;
    for (uint32_t i = 1; i <= scene.frames && !interrupt_signal(); ++i) {
      t = Clock::now();
      const sph_result step = runtime.step_frame();
      const double step_ms = ms_since(t);
      if (interrupt_signal()) break;  // the frame is not written: only whole frames stay
      for (const std::string& w : runtime.warnings()) progress.note("sph-run: warning: " + w);
      if (step == SPH_INCOMPLETE)
        progress.note("sph-run: warning: frame " + std::to_string(i) +
                      ": max_substeps ran out before the frame's end (raise params.max_substeps or dt_min)");
      sph_stats s;
      sph_stats_init(&s);
      sph_world_get_stats(runtime.world(), &s);
      t = Clock::now();
      read_particles(runtime.world(), i, runtime.time(), &frame);
      writer.write(runtime, frame);
      const double output_ms = ms_since(t);
      ++written;
      stats.add_frame(s, step_ms, output_ms);
      progress.frame_done(FrameReport{i, s.particle_count, s.substeps, step_ms, output_ms});
    }
    progress.finish();
    const int signal = interrupt_signal();
    if (signal)
      std::fprintf(stderr, "sph-run: interrupted; frames 0..%u are complete in %s/\n", written - 1,
                   out.directory.c_str());
    if (out.preview && !signal) {
      const std::string mp4 = out.directory + "/preview.mp4";
      if (!ffmpeg_on_path()) {
        if (!cli.quiet)
          std::fprintf(stderr, "sph-run: no ffmpeg on PATH: no preview.mp4 (the PNGs are there)\n");
      } else {
        const std::string problem = encode_mp4(out.directory + "/preview_%04d.png", 0, scene.fps, mp4);
        if (!problem.empty())
          std::fprintf(stderr, "sph-run: warning: preview.mp4: %s\n", problem.c_str());
        else if (!cli.quiet)
          std::fprintf(stderr, "sph-run: wrote %s\n", mp4.c_str());
      }
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - run_start).count();
    stats.print(stdout,
                cli.scene + ": " + std::to_string(stats.frames()) + " frames (" + std::to_string(written) +
                    " written to " + out.directory + "/)",
                backend_name, wall_s);
    std::fflush(stdout);
    return signal ? kExitInterrupted + signal : kExitOk;
  } catch (const SceneError& e) {
    return fail(kExitScene, cli.scene + ": " + e.what());
  } catch (const LibraryError& e) {
    return fail(kExitRuntime, e.what());
  } catch (const std::exception& e) {
    return fail(kExitRuntime, e.what());
  }
}

}  // namespace
}  // namespace sph_tools

int main(int argc, char** argv) { return sph_tools::run(argc, argv); }
