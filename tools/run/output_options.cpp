// SPDX-License-Identifier: MIT
#include "output_options.h"

#include "exit_codes.h"
#include "image.h"
#include "json_node.h"

namespace sph_tools {

namespace {

std::string file_stem(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

int refuse(int code, const std::string& why, std::string* message) {
  *message = why;
  return code;
}

}  // namespace

int resolve_output_options(const CliOptions& cli, const SceneDesc& scene, FrameWriterOptions* out,
                           std::string* message) {
  out->directory = cli.out                           ? *cli.out
                   : !scene.output.directory.empty() ? scene.output.directory
                                                     : "out/" + file_stem(cli.scene);
  if (cli.formats) {
    out->formats = *cli.formats;
  } else if (!scene.output.formats.empty()) {
    out->formats = scene.output.formats;
  } else {
    out->formats = {format_available(OutputFormat::kVdb) ? OutputFormat::kVdb : OutputFormat::kPly};
  }
  for (OutputFormat f : out->formats)
    if (!format_available(f))
      return refuse(kExitUnavailable,
                    std::string("--format ") + format_extension(f) +
                        ": this build has no OpenVDB; use ply or csv (" +
                        (cli.formats ? "from the command line" : "from output.format") + ")",
                    message);
  out->surface = cli.surface || scene.output.surface;
  if (out->surface && !surface_available())
    return refuse(kExitUnavailable,
                  std::string(cli.surface ? "--surface" : "output.surface") +
                      ": surfaces need OpenVDB, which this build lacks",
                  message);
  out->preview = cli.preview || scene.output.preview;
  if (out->preview && !png_available())
    return refuse(kExitUnavailable,
                  std::string(cli.preview ? "--preview" : "output.preview") +
                      ": preview images need libpng, which this build lacks (install libpng-dev)",
                  message);
  out->preview_surface = cli.preview_surface ? *cli.preview_surface : scene.output.preview_surface;
  if (cli.preview_surface.value_or(false) && !out->surface)
    return refuse(
        kExitUsage,
        "--preview-style surface: draws the surface mesh, so it needs --surface (or output.surface)",
        message);
  const float spacing = scene.world.particle_spacing;
  out->surface_radius = scene.output.surface_radius > 0.0f ? scene.output.surface_radius : spacing;
  out->surface_voxel = scene.output.surface_voxel > 0.0f ? scene.output.surface_voxel : 0.5f * spacing;
  if (out->surface && out->surface_radius < 1.5f * out->surface_voxel)
    return refuse(kExitScene,
                  cli.scene + ": output.surface.particle_radius: expected at least 1.5 voxels (" +
                      number_text(1.5f * out->surface_voxel) + " m)",
                  message);
  // Each particle is rasterised as a sphere of radius/voxel voxels: past 16 the level set's size
  // (and its time) grows as the cube of that ratio with nothing to gain for a fluid surface (a
  // 1e-5 m voxel under a 0.02 m particle asked for 2000 voxels a radius and ran out of memory).
  if (out->surface && out->surface_radius > 16.0f * out->surface_voxel)
    return refuse(kExitScene,
                  cli.scene +
                      ": output.surface.voxel_size: expected at least 1/16 of the particle "
                      "radius (" +
                      number_text(out->surface_radius / 16.0f) + " m)",
                  message);
  return kExitOk;
}

}  // namespace sph_tools
