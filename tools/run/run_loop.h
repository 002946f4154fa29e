// SPDX-License-Identifier: MIT
// The run itself: a built scene stepped frame by frame, every frame written, progress shown,
// the summary printed at the end.
#ifndef SPH_TOOLS_RUN_LOOP_H
#define SPH_TOOLS_RUN_LOOP_H

#include <string>

#include "cli_options.h"
#include "frame_writer.h"
#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

// Plays `scene` on a world of `context` and returns sph-run's exit code. When the backend
// refuses the scene at its first step (SPH_ERROR_UNSUPPORTED: a feature it does not have),
// nothing is printed: *backend_refused is set, *why holds the library's message, and the
// caller may try another backend (only frame 0 has been written).
int run_scene(sph_context* context, const std::string& backend_name, const SceneDesc& scene,
              const FrameWriterOptions& out, const CliOptions& cli, bool* backend_refused, std::string* why);

}  // namespace sph_tools

#endif
