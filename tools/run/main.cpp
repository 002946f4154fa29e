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
#include "json_node.h"
#include "library_error.h"
#include "run_loop.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "sph_c.h"
#include "vdb_bounds.h"

namespace sph_tools {
namespace {

std::string file_stem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

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
  if (out.preview && !png_available())
    return fail(kExitUnavailable,
                std::string(cli.preview ? "--preview" : "output.preview") +
                    ": preview images need libpng, which this build lacks (install libpng-dev)");
  out.preview_surface = cli.preview_surface ? *cli.preview_surface : scene.output.preview_surface;
  if (cli.preview_surface.value_or(false) && !out.surface)
    return fail(kExitUsage,
                "--preview-style surface: draws the surface mesh, so it needs --surface (or output.surface)");
  const float spacing = scene.world.particle_spacing;
  out.surface_radius = scene.output.surface_radius > 0.0f ? scene.output.surface_radius : spacing;
  out.surface_voxel = scene.output.surface_voxel > 0.0f ? scene.output.surface_voxel : 0.5f * spacing;
  if (out.surface && out.surface_radius < 1.5f * out.surface_voxel)
    return fail(kExitScene, cli.scene + ": output.surface.particle_radius: expected at least 1.5 voxels (" +
                                number_text(1.5f * out.surface_voxel) + " m)");
  // Each particle is rasterised as a sphere of radius/voxel voxels: past 16 the level set's size
  // (and its time) grows as the cube of that ratio with nothing to gain for a fluid surface (a
  // 1e-5 m voxel under a 0.02 m particle asked for 2000 voxels a radius and ran out of memory).
  if (out.surface && out.surface_radius > 16.0f * out.surface_voxel)
    return fail(kExitScene, cli.scene +
                                ": output.surface.voxel_size: expected at least 1/16 of the particle "
                                "radius (" +
                                number_text(out.surface_radius / 16.0f) + " m)");

  // ---- the backend and the world ---------------------------------------------------------------
  ContextOwner owner;
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
