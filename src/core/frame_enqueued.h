// SPDX-License-Identifier: MIT
// A call made once a frame's device work is all enqueued, before the backend waits for it:
// sph_cuda_world_step_begin_on_stream makes the caller's CUDA stream wait for the frame there.
// The CUDA backend calls it after the frame graph's launch, or after the stream driver's last
// substep (which the host drove, so the frame is done by then); a frame that fails before that
// point never calls it, and the caller must cope (the C layer raises its signal when the step
// ends, whatever happened). A hook that throws fails the frame, which then rolls back.
#pragma once

#include <functional>

namespace sph {

using FrameEnqueuedHook = std::function<void()>;

}  // namespace sph
