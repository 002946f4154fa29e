// SPDX-License-Identifier: MIT
// The output options of a run (directory, formats, surface, preview) as sph-run and sph-run-mpi
// resolve them: the command line over the scene file over the defaults, checked against what
// the build can write (docs/cli.md).
#ifndef SPH_TOOLS_OUTPUT_OPTIONS_H
#define SPH_TOOLS_OUTPUT_OPTIONS_H

#include <string>

#include "cli_options.h"
#include "frame_writer.h"
#include "scene_desc.h"

namespace sph_tools {

// Fills *out; returns kExitOk, or the exit code (exit_codes.h) with *message saying what is
// wrong (an output this build lacks, a surface voxel out of range, ...), without the program's
// name. The default format is vdb where the build has OpenVDB, else ply.
int resolve_output_options(const CliOptions& cli, const SceneDesc& scene, FrameWriterOptions* out,
                           std::string* message);

}  // namespace sph_tools

#endif
