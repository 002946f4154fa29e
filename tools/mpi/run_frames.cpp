// SPDX-License-Identifier: MIT
#include "run_frames.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "distributed_maker.h"
#include "interrupt.h"
#include "library_error.h"
#include "load_csv.h"
#include "merged_frame.h"
#include "message_fold.h"
#include "particle_frame.h"
#include "probe_csv.h"
#include "progress.h"
#include "run_stats.h"
#include "scene_runtime.h"
#include "sph_mpi.h"
#include "video.h"
#include "world_stats.h"

namespace sph_tools {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Rank 0's files besides the frames: the probes' and the colliders' loads, as sph-run writes
// them (tools/run). The readings are the world's on every rank (sph_mpi.h), so rank 0 reads
// its own copy.
struct ObjectFiles {
  LoadCsv loads;
  ProbeCsv probes;

  // Opens the files and records them in `writer`'s manifest (a later run removes them).
  void open(const Ranks& ranks, const std::string& directory, const SceneRuntime& runtime,
            FrameWriter& writer) {
    std::string problem = loads.open(directory, runtime);
    writer.record_tables(loads.names());
    if (!problem.empty()) abort_run(ranks, "loads: cannot write " + problem);
    problem = probes.open(directory, runtime);
    writer.record_tables(probes.names());
    if (!problem.empty()) abort_run(ranks, "probes: cannot write " + problem);
  }
  void write(const Ranks& ranks, const SceneRuntime& runtime, uint32_t frame) {
    std::string problem = loads.write(runtime, frame, runtime.time());
    if (!problem.empty()) abort_run(ranks, "loads: cannot write " + problem);
    problem = probes.write(runtime, frame, runtime.time());
    if (!problem.empty()) abort_run(ranks, "probes: cannot write " + problem);
  }
  void close(const Ranks& ranks) {
    std::string problem = loads.close();
    if (!problem.empty()) abort_run(ranks, "loads: cannot write " + problem);
    problem = probes.close();
    if (!problem.empty()) abort_run(ranks, "probes: cannot write " + problem);
  }
};

}  // namespace

int run_frames(const Ranks& ranks, const CliOptions& cli, const SceneDesc& scene,
               const FrameWriterOptions& out, bool per_rank, sph_context* context) {
  DistributedMaker maker(static_cast<int32_t>(MPI_Comm_c2f(ranks.comm)), ranks.rank);
  SceneRuntime runtime(scene, context, &maker);
  ManifestHeader header;
  header.scene = cli.scene;
  header.fps = scene.fps;
  header.frames = scene.frames;
  const bool root = ranks.rank == 0;
  // Rank 0 makes the output directory before the others make their folders in it.
  std::unique_ptr<FrameWriter> merged, own_writer;
  try {
    if (root) merged = std::make_unique<FrameWriter>(out, runtime, header);
  } catch (const std::exception& e) {
    abort_run(ranks, e.what());
  }
  MPI_Barrier(ranks.comm);
  try {
    if (per_rank) {
      FrameWriterOptions mine = out;
      mine.directory = out.directory + "/rank" + std::to_string(ranks.rank);
      mine.preview = false;
      // The surface is the merged world's alone: a rank's own would be cut open at its slab's faces.
      mine.surface = false;
      own_writer = std::make_unique<FrameWriter>(mine, runtime, header);
    }
  } catch (const std::exception& e) {
    abort_run(ranks, e.what());
  }
  const std::string backend = cli.backend == SPH_BACKEND_CUDA ? "CUDA" : "CPU";
  if (root && !cli.quiet)
    std::fprintf(stderr, "sph-run-mpi: %s: %u frames at %g fps on %d ranks (%s) -> %s/%s\n",
                 cli.scene.c_str(), scene.frames, static_cast<double>(scene.fps), ranks.count,
                 backend.c_str(), out.directory.c_str(), per_rank ? " (+ rank<R>/)" : "");
  install_interrupt_handlers();
  Progress progress(scene.frames, isatty(STDERR_FILENO) != 0, cli.quiet || !root);
  FrameMessages messages("sph-run-mpi");
  RunStats stats;  // the world's figures (world_stats), kept by rank 0
  ObjectFiles objects;
  ParticleFrame own, all;
  const auto start = Clock::now();
  // Frame i: this rank's particles, merged on rank 0, written. Returns the output's wall ms.
  const auto write_frame = [&](uint32_t i) {
    const auto w = Clock::now();
    read_particles(runtime.world(), i, runtime.time(), &own);
    gather_frame(runtime.world(), ranks.comm, own, &all);
    try {
      if (merged) merged->write(runtime, all);
      if (own_writer) own_writer->write(runtime, own);
    } catch (const std::exception& e) {
      abort_run(ranks, e.what());
    }
    if (root && i > 0) objects.write(ranks, runtime, i);
    return ms_since(w);
  };
  const auto add_output_kinds = [&] {
    if (merged)
      stats.add_output_kinds(merged->times().particles_ms, merged->times().surface_ms,
                             merged->times().preview_ms);
  };
  stats.add_output(write_frame(0));
  add_output_kinds();
  if (root) objects.open(ranks, out.directory, runtime, *merged);
  uint32_t written = 1;
  int signal = 0;
  for (uint32_t i = 1; i <= scene.frames; ++i) {
    // The ranks agree before each step and after it, so that all stop after the same frame: a
    // frame whose step a signal interrupted is dropped on every rank, as sph-run drops it.
    signal = agreed_signal(interrupt_signal(), ranks.comm);
    if (signal) break;
    const auto t = Clock::now();
    const sph_result step = runtime.step_frame();
    const double step_ms = ms_since(t);
    sph_stats s;
    sph_stats_init(&s);
    sph_world_get_stats(runtime.world(), &s);
    const sph_stats world = world_stats(s, interrupt_signal(), ranks.comm, &signal);
    if (signal) break;
    if (root) {
      messages.frame(progress, i, runtime, step);
    }
    const double output_ms = write_frame(i);
    ++written;
    stats.add_frame(world, step_ms, output_ms);
    add_output_kinds();
    progress.frame_done(
        FrameReport{i, world.particle_count, world.substeps, step_ms, output_ms, world.pressure_iterations});
  }
  progress.finish();
  if (root) messages.print_closing(stderr);
  if (root) objects.close(ranks);
  if (signal && root)
    std::fprintf(stderr, "sph-run-mpi: interrupted; frames 0..%u are complete in %s/\n", written - 1,
                 out.directory.c_str());
  if (merged && out.preview && !signal) {
    if (!ffmpeg_on_path()) {
      if (!cli.quiet)
        std::fprintf(stderr, "sph-run-mpi: no ffmpeg on PATH: no preview.mp4 (the PNGs are there)\n");
    } else {
      const std::string problem = merged->write_preview_video(scene.fps);
      if (!problem.empty()) std::fprintf(stderr, "sph-run-mpi: warning: preview.mp4: %s\n", problem.c_str());
    }
  }
  const char* end = signal ? "interrupted" : "complete";
  if (merged) merged->end(end, written - 1);
  if (own_writer) own_writer->end(end, written - 1);
  sph_mpi_counts counts;
  sph_mpi_counts_init(&counts);
  const sph_result r = sph_mpi_world_get_counts(runtime.world(), &counts);
  if (r < 0) throw LibraryError(r, "reading the distributed world's counts");
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (root) {
    std::printf(
        "%s: %u frames on %d ranks (%u written to %s/): %llu particles, %llu substeps, %llu migrations, "
        "%u rebalances, %.2f s\n",
        cli.scene.c_str(), written - 1, ranks.count, written, out.directory.c_str(),
        static_cast<unsigned long long>(counts.global_count),
        static_cast<unsigned long long>(stats.substeps()), static_cast<unsigned long long>(counts.migrated),
        counts.rebalances, wall_s);
    stats.print_solves(stdout);
    std::fflush(stdout);
  }
  if (root && cli.stats_json) {
    // sph-run's document, with the distribution's own figures after it.
    const std::string extra = "\"ranks\": " + std::to_string(ranks.count) +
                              ", \"migrated\": " + std::to_string(counts.migrated) +
                              ", \"rebalances\": " + std::to_string(counts.rebalances) +
                              ", \"ghosts_last_substep\": " + std::to_string(counts.global_ghosts);
    const std::string problem = stats.write_json(*cli.stats_json, cli.scene, backend, wall_s, extra);
    if (!problem.empty()) {
      std::fprintf(stderr, "sph-run-mpi: --stats-json: cannot write %s: %s\n", cli.stats_json->c_str(),
                   problem.c_str());
      return kExitRuntime;
    }
  }
  return signal ? kExitInterrupted + signal : kExitOk;
}

}  // namespace sph_tools
