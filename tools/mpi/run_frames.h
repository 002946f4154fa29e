// SPDX-License-Identifier: MIT
// sph-run-mpi's run: the scene's world made distributed, stepped frame by frame on every rank,
// the merged frames (and the probes' and loads' CSV files) written by rank 0.
#ifndef SPH_TOOLS_RUN_FRAMES_H
#define SPH_TOOLS_RUN_FRAMES_H

#include "cli_options.h"
#include "frame_writer.h"
#include "ranks.h"
#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

// COLLECTIVE. Plays `scene` on every rank and returns sph-run's exit code (0, or 128 + the
// signal when a rank was interrupted: every rank stops after the same frame). Throws
// SceneError and LibraryError as every rank meets them alike; a failure of one rank's files
// ends the run through abort_run.
int run_frames(const Ranks& ranks, const CliOptions& cli, const SceneDesc& scene,
               const FrameWriterOptions& out, bool per_rank, sph_context* context);

}  // namespace sph_tools

#endif
