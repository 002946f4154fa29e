// SPDX-License-Identifier: MIT
// sph-run-mpi: sph-run's scene files on a distributed world (sph_mpi.h), one process per rank
// under mpirun (docs/distributed.md, "sph-run under mpirun"). Every rank reads the scene and
// builds the same colliders, sinks, sources, probes and force fields; rank 0 adds the fluid
// bodies; rank 0 writes the merged frames (every rank's particles, by id), the probes' and
// loads' files and, with --per-rank, each rank its own frames into DIR/rank<R>/ (run_frames).
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "cli_options.h"
#include "exit_codes.h"
#include "frame_writer.h"
#include "image.h"
#include "library_error.h"
#include "output_options.h"
#include "ranks.h"
#include "run_frames.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "sph_mpi.h"
#include "vdb_bounds.h"

namespace sph_tools {
namespace {

const char* const kMpiUsage =
    "\n"
    "sph-run-mpi runs the scene on a distributed world, one process per rank:\n"
    "  mpirun -np 2 sph-run-mpi SCENE.json [options]\n"
    "Rank 0 writes the merged frames (every rank's particles, by id) to the output directory.\n"
    "  --per-rank          also write each rank's own particles to DIR/rank<R>/\n"
    "  --backend cuda      every rank on the CUDA backend, on the GPU of its node-local rank (or GPU 0\n"
    "                      where there is no such GPU; the host-staged halo); auto and cpu: the CPU\n"
    "Rank 0 writes the probes' and loads' CSV files and --stats-json (the world's figures).\n"
    "Ctrl-C (SIGINT or SIGTERM on any rank) stops every rank after the same frame.\n"
    "The vdb frames and surfaces are the merged world's (rank<R>/ holds no surface); the ranks refuse\n"
    "what docs/distributed.md lists.\n";

struct ContextOwner {
  sph_context* context = nullptr;
  ~ContextOwner() { sph_context_destroy(context); }
};

// A failure every rank meets at the same point (the same scene, the same collective calls):
// rank 0 says it, every rank returns the code and finalises.
int fail(const Ranks& r, int code, const std::string& message) {
  if (r.rank == 0) std::fprintf(stderr, "sph-run-mpi: %s\n", message.c_str());
  return code;
}

// The rank's context: the CPU backend for cpu and auto (a distributed world's ranks all need the
// same backend, which auto cannot promise across nodes); for cuda the GPU of the node-local rank,
// so that a node's ranks spread over its GPUs, or GPU 0 where the node has fewer GPUs than ranks
// (ranks then share it, as the host-staged halo allows; docs/distributed.md).
sph_result create_context(const Ranks& ranks, const CliOptions& cli, sph_context** out) {
  sph_context_def def;
  sph_context_def_init(&def);
  def.cpu_worker_count = cli.threads;
  if (cli.dfsph_lists) def.cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS;  // the CPU ignores it
  if (cli.backend != SPH_BACKEND_CUDA) {
    def.backend = SPH_BACKEND_CPU;
    return sph_context_create(&def, out);
  }
  MPI_Comm node;
  int local = 0;
  MPI_Comm_split_type(ranks.comm, MPI_COMM_TYPE_SHARED, ranks.rank, MPI_INFO_NULL, &node);
  MPI_Comm_rank(node, &local);
  MPI_Comm_free(&node);
  def.backend = SPH_BACKEND_CUDA;
  def.device_ordinal = local;
  sph_result r = sph_context_create(&def, out);
  if (r < 0 && local != 0) {
    def.device_ordinal = 0;
    r = sph_context_create(&def, out);
    if (r >= 0 && !cli.quiet)
      std::fprintf(stderr, "sph-run-mpi: rank %d: no GPU %d on this node; sharing GPU 0\n", ranks.rank,
                   local);
  }
  return r;
}

int run(const Ranks& ranks, int argc, char** argv) {
  // --per-rank is sph-run-mpi's own; the rest is sph-run's command line.
  bool per_rank = false;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (i > 0 && std::strcmp(argv[i], "--per-rank") == 0)
      per_rank = true;
    else
      args.push_back(argv[i]);
  }
  CliOptions cli;
  try {
    cli = parse_cli(static_cast<int>(args.size()), args.data());
  } catch (const UsageError& e) {
    return fail(ranks, kExitUsage, std::string(e.what()) + "\n  (sph-run-mpi --help lists the options)");
  }
  if (cli.help || cli.version) {
    if (ranks.rank == 0 && cli.help) std::printf("%s%s", usage_text(), kMpiUsage);
    if (ranks.rank == 0 && cli.version) {
      std::printf("sph-run-mpi, %s\n", sph_get_build_info());
      std::printf(
          "outputs: csv, ply, vtp (+ fluid.pvd)%s%s%s\n", format_available(OutputFormat::kVdb) ? ", vdb" : "",
          surface_available() ? ", surfaces (vdb + obj)" : "", png_available() ? ", preview (png)" : "");
    }
    return kExitOk;
  }
  SceneDesc scene;
  try {
    scene = load_scene_file(cli.scene);
  } catch (const SceneError& e) {
    return fail(ranks, kExitScene, cli.scene + ": " + e.what());
  }
  if (cli.frames) scene.frames = *cli.frames;
  fill_vdb_bounds(&scene);  // the extent of .vdb level sets, for the preview
  // sph-run's outputs, vdb frames and surfaces included where the build has OpenVDB.
  FrameWriterOptions out;
  std::string problem;
  const int unavailable = resolve_output_options(cli, scene, &out, &problem);
  if (unavailable != kExitOk) return fail(ranks, unavailable, problem);

  ContextOwner owner;
  const sph_result r = create_context(ranks, cli, &owner.context);
  // Every rank learns whether every rank has its context before the world's collective creation.
  int worst = r < 0 ? static_cast<int>(r) : 0;
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_INT, MPI_MIN, ranks.comm);
  if (worst < 0) {
    if (cli.backend == SPH_BACKEND_CUDA)
      return fail(ranks, kExitBackend,
                  std::string("--backend cuda: the CUDA backend is not available on every rank (") +
                      (r < 0 ? sph_get_last_error() : "another rank's") + ")\n  (use --backend cpu)");
    return fail(ranks, kExitRuntime,
                LibraryError(static_cast<sph_result>(worst), "creating the context").what());
  }
  try {
    return run_frames(ranks, cli, scene, out, per_rank, owner.context);
  } catch (const SceneError& e) {
    return fail(ranks, kExitScene, cli.scene + ": " + e.what());
  } catch (const LibraryError& e) {
    // A feature the ranks refuse after the world's creation (DFSPH's conjugate gradients with the
    // walls' density or the loads, on every rank alike): a scene this program cannot run, as the world's own
    // refusals are.
    return fail(ranks, e.code() == SPH_ERROR_UNSUPPORTED ? kExitScene : kExitRuntime, e.what());
  }
}

}  // namespace
}  // namespace sph_tools

int main(int argc, char** argv) {
  if (MPI_Init(&argc, &argv) != MPI_SUCCESS) {
    std::fprintf(stderr, "sph-run-mpi: MPI_Init failed\n");
    return sph_tools::kExitRuntime;
  }
  sph_tools::Ranks ranks;
  MPI_Comm_rank(ranks.comm, &ranks.rank);
  MPI_Comm_size(ranks.comm, &ranks.count);
  int code = sph_tools::kExitRuntime;
  try {
    code = sph_tools::run(ranks, argc, argv);
  } catch (const std::bad_alloc&) {
    sph_tools::abort_run(ranks, "out of memory");
  } catch (const std::exception& e) {
    sph_tools::abort_run(ranks, e.what());
  }
  MPI_Finalize();
  return code;
}
