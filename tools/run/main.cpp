// SPDX-License-Identifier: MIT
// sph-run: runs a scene file and writes its frames (docs/cli.md).
#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "cli_options.h"
#include "exit_codes.h"
#include "frame_writer.h"
#include "image.h"
#include "library_error.h"
#include "output_options.h"
#include "run_loop.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "sph_c.h"
#include "vdb_bounds.h"

namespace sph_tools {
namespace {

struct ContextOwner {
  sph_context* context = nullptr;
  ~ContextOwner() { sph_context_destroy(context); }
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
    std::fprintf(stderr, "sph-run: %s\n  (sph-run --help lists the options)\n", e.what());
    return kExitUsage;
  }
  if (cli.help) {
    std::fputs(usage_text(), stdout);
    return kExitOk;
  }
  if (cli.version) {
    std::printf("sph-run, %s\n", sph_get_build_info());
    std::printf(
        "outputs: csv, ply, vtp (+ fluid.pvd)%s%s%s\n", format_available(OutputFormat::kVdb) ? ", vdb" : "",
        surface_available() ? ", surfaces (vdb + obj)" : "", png_available() ? ", preview (png)" : "");
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
  fill_vdb_bounds(&scene);  // the extent of .vdb level sets, for the preview
  FrameWriterOptions out;
  std::string problem;
  const int unavailable = resolve_output_options(cli, scene, &out, &problem);
  if (unavailable != kExitOk) return fail(unavailable, problem);

  // ---- the backend and the world ---------------------------------------------------------------
  ContextOwner owner;
  sph_context_def context_def;
  sph_context_def_init(&context_def);
  context_def.backend = cli.backend;
  context_def.cpu_worker_count = cli.threads;
  // A CPU context and a weakly compressible world check and ignore it.
  if (cli.dfsph_lists) context_def.cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS;
  sph_result r = sph_context_create(&context_def, &owner.context);
  if (r == SPH_ERROR_UNSUPPORTED)
    return fail(kExitBackend, std::string("the ") + (cli.backend == SPH_BACKEND_CUDA ? "CUDA" : "requested") +
                                  " backend is not available: " + sph_get_last_error() +
                                  "\n  (use --backend cpu, or auto to take a GPU only when there is one)");
  if (r < 0) return fail(kExitRuntime, LibraryError(r, "creating the context").what());
  sph_backend used = SPH_BACKEND_CPU;
  sph_context_get_backend(owner.context, &used);
  const std::string backend_name = used == SPH_BACKEND_CUDA ? "CUDA" : "CPU";

  bool refused = false;
  std::string why;
  int code = run_scene(owner.context, backend_name, scene, out, cli, &refused, &why);
  if (refused && cli.backend == SPH_BACKEND_AUTO && used == SPH_BACKEND_CUDA) {
    // --backend auto took the GPU, whose backend cannot run this scene: say so and use the CPU.
    std::fprintf(stderr,
                 "sph-run: warning: the CUDA backend cannot run this scene (%s); running it on the CPU\n",
                 why.c_str());
    ContextOwner cpu;
    context_def.backend = SPH_BACKEND_CPU;
    r = sph_context_create(&context_def, &cpu.context);
    if (r < 0) return fail(kExitRuntime, LibraryError(r, "creating a CPU context").what());
    code = run_scene(cpu.context, "CPU", scene, out, cli, &refused, &why);
  }
  if (refused)
    return fail(kExitBackend, "the " + backend_name + " backend cannot run this scene: " + why +
                                  "\n  (use --backend cpu, or auto to fall back to the CPU)");
  return code;
}

}  // namespace
}  // namespace sph_tools

// Nothing escapes: every failure is a message and an exit code of docs/cli.md.
int main(int argc, char** argv) {
  // A write past the file size limit (ulimit -f) fails with EFBIG, which the writers report,
  // instead of killing the process with SIGXFSZ halfway through a frame.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    return sph_tools::run(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sph-run: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sph-run: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "sph-run: an unknown error\n");
  }
  return sph_tools::kExitRuntime;
}
