// SPDX-License-Identifier: MIT
// An MP4 of the preview frames through the ffmpeg program, when it is on PATH.
#ifndef SPH_TOOLS_VIDEO_H
#define SPH_TOOLS_VIDEO_H

#include <string>

namespace sph_tools {

// Whether an executable `ffmpeg` is on PATH.
bool ffmpeg_on_path();

// Encodes `pattern` (a printf pattern such as "dir/preview_%04d.png") from frame
// `first_frame` at `fps` into `mp4_path` (H.264, yuv420p), through a temporary name. Returns ""
// on success, else what went wrong.
std::string encode_mp4(const std::string& pattern, unsigned first_frame, float fps,
                       const std::string& mp4_path);

}  // namespace sph_tools

#endif
