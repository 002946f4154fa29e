// SPDX-License-Identifier: MIT
#include "run_loop.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <new>

#include "exit_codes.h"
#include "frame_writer.h"
#include "interrupt.h"
#include "library_error.h"
#include "load_csv.h"
#include "message_fold.h"
#include "particle_frame.h"
#include "probe_csv.h"
#include "progress.h"
#include "run_stats.h"
#include "scene_error.h"
#include "scene_runtime.h"
#include "video.h"

namespace sph_tools {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

int fail(int code, const std::string& message) {
  std::fprintf(stderr, "sph-run: %s\n", message.c_str());
  return code;
}

}  // namespace

int run_scene(sph_context* context, const std::string& backend_name, const SceneDesc& scene,
              const FrameWriterOptions& out, const CliOptions& cli, bool* backend_refused, std::string* why) {
  *backend_refused = false;
  const bool tty = isatty(STDERR_FILENO) != 0;
  uint32_t stepped = 0;
  try {
    SceneRuntime runtime(scene, context);
    ManifestHeader header;
    header.scene = cli.scene;
    header.fps = scene.fps;
    header.frames = scene.frames;
    FrameWriter writer(out, runtime, header);
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
    FrameMessages messages("sph-run");
    RunStats stats;
    ParticleFrame frame;
    const Clock::time_point run_start = Clock::now();

    Clock::time_point t = Clock::now();
    read_particles(runtime.world(), 0, 0.0, &frame);
    writer.write(runtime, frame);
    stats.add_output(ms_since(t));
    stats.add_output_kinds(writer.times().particles_ms, writer.times().surface_ms, writer.times().preview_ms);
    uint32_t written = 1;
    LoadCsv loads;  // the colliders that ask for their loads (scene file "loads")
    const std::string loads_problem = loads.open(out.directory, runtime);
    writer.record_tables(loads.names());  // so that a later run removes them (docs/cli.md)
    if (!loads_problem.empty()) return fail(kExitRuntime, "loads: cannot write " + loads_problem);
    ProbeCsv probes;  // the scene file's "probes"
    const std::string probes_problem = probes.open(out.directory, runtime);
    writer.record_tables(probes.names());
    if (!probes_problem.empty()) return fail(kExitRuntime, "probes: cannot write " + probes_problem);
    for (uint32_t i = 1; i <= scene.frames && !interrupt_signal(); ++i) {
      t = Clock::now();
      const sph_result step = runtime.step_frame();
      ++stepped;
      const double step_ms = ms_since(t);
      if (interrupt_signal()) break;  // the frame is not written: only whole frames stay
      messages.frame(progress, i, runtime, step);
      sph_stats s;
      sph_stats_init(&s);
      sph_world_get_stats(runtime.world(), &s);
      t = Clock::now();
      read_particles(runtime.world(), i, runtime.time(), &frame);
      writer.write(runtime, frame);
      const std::string load_problem = loads.write(runtime, i, runtime.time());
      if (!load_problem.empty()) return fail(kExitRuntime, "loads: cannot write " + load_problem);
      const std::string probe_problem = probes.write(runtime, i, runtime.time());
      if (!probe_problem.empty()) return fail(kExitRuntime, "probes: cannot write " + probe_problem);
      const double output_ms = ms_since(t);
      ++written;
      stats.add_frame(s, step_ms, output_ms);
      stats.add_output_kinds(writer.times().particles_ms, writer.times().surface_ms,
                             writer.times().preview_ms);
      progress.frame_done(
          FrameReport{i, s.particle_count, s.substeps, step_ms, output_ms, s.pressure_iterations});
    }
    progress.finish();
    messages.print_closing(stderr);
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
        const std::string problem = writer.write_preview_video(scene.fps);
        if (!problem.empty())
          std::fprintf(stderr, "sph-run: warning: preview.mp4: %s\n", problem.c_str());
        else if (!cli.quiet)
          std::fprintf(stderr, "sph-run: wrote %s\n", mp4.c_str());
      }
    }
    writer.end(signal ? "interrupted" : "complete", written - 1);
    const double wall_s = std::chrono::duration<double>(Clock::now() - run_start).count();
    stats.print(stdout,
                cli.scene + ": " + std::to_string(stats.frames()) + " frames (" + std::to_string(written) +
                    " written to " + out.directory + "/)",
                backend_name, wall_s);
    std::fflush(stdout);
    if (cli.stats_json) {
      const std::string problem = stats.write_json(*cli.stats_json, cli.scene, backend_name, wall_s);
      if (!problem.empty())
        return fail(kExitRuntime, "--stats-json: cannot write " + *cli.stats_json + ": " + problem);
    }
    return signal ? kExitInterrupted + signal : kExitOk;
  } catch (const SceneError& e) {
    return fail(kExitScene, cli.scene + ": " + e.what());
  } catch (const LibraryError& e) {
    if (e.code() == SPH_ERROR_UNSUPPORTED && stepped == 0) {
      // The backend refused the scene at its first step: the caller decides what to do.
      *backend_refused = true;
      const std::string message = e.what();
      const size_t cut = message.find("\n  ");
      *why = cut == std::string::npos ? message : message.substr(cut + 3);
      return kExitBackend;
    }
    return fail(kExitRuntime, e.what());
  } catch (const std::bad_alloc&) {
    return fail(kExitRuntime, "out of memory");
  } catch (const std::exception& e) {
    return fail(kExitRuntime, e.what());
  } catch (...) {
    return fail(kExitRuntime, "an unknown error");
  }
}

}  // namespace sph_tools
