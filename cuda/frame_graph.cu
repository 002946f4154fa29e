// SPDX-License-Identifier: MIT
#include <vector>

#include "frame_graph.h"
#include "graph_while_node.h"

namespace sph {
namespace {

// Ends a capture that failed half-way, so the stream is usable again.
void abandon_capture(cudaStream_t stream) {
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  if (cudaStreamIsCapturing(stream, &status) == cudaSuccess && status != cudaStreamCaptureStatusNone) {
    cudaGraph_t partial = nullptr;
    if (cudaStreamEndCapture(stream, &partial) == cudaSuccess && partial) cudaGraphDestroy(partial);
  }
  (void)cudaGetLastError();
}

constexpr cudaStreamCaptureMode kCaptureMode = cudaStreamCaptureModeThreadLocal;

}  // namespace

void FrameGraph::reset() noexcept {
  if (exec_ && cudaGraphExecDestroy(exec_) != cudaSuccess) (void)cudaGetLastError();
  if (graph_ && cudaGraphDestroy(graph_) != cudaSuccess) (void)cudaGetLastError();
  exec_ = nullptr;
  graph_ = nullptr;
}

void FrameGraph::build(const PipelineSetup& setup, const PipelineBuffers& buffers, cudaStream_t stream) {
  reset();
  try {
    cuda_check(cudaGraphCreate(&graph_, 0), "cudaGraphCreate");
    LoopCondition cond;
    cond.in_graph = true;
    cuda_check(cudaGraphConditionalHandleCreate(&cond.handle, graph_, 0, cudaGraphCondAssignDefault),
               "cudaGraphConditionalHandleCreate");

    // 1. begin segment, captured into the frame graph.
    cuda_check(cudaStreamBeginCaptureToGraph(stream, graph_, nullptr, nullptr, 0, kCaptureMode),
               "capture of the frame begin");
    enqueue_frame_begin(setup, buffers, cond, stream);

    // 2. the WHILE node; its body is one substep. The capture resumes after it.
    capture_while_node(cond.handle, stream, [&] { enqueue_substep(setup, buffers, cond, stream); });

    // 3. end segment after the loop.
    enqueue_frame_end(setup, buffers, stream);
    cuda_check(cudaStreamEndCapture(stream, &graph_), "capture of the frame end");

    cuda_check(cudaGraphInstantiate(&exec_, graph_, 0), "cudaGraphInstantiate");
  } catch (...) {
    abandon_capture(stream);
    reset();
    throw;
  }
}

void FrameGraph::launch(cudaStream_t stream) const {
  cuda_check(cudaGraphLaunch(exec_, stream), "cudaGraphLaunch");
}

}  // namespace sph
