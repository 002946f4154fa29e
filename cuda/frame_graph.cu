// SPDX-License-Identifier: MIT
#include <vector>

#include "frame_graph.h"
#include "graph_while_node.h"

namespace sph {
namespace {

// Ends a capture that failed half-way, so the stream is usable again. Every capture here goes
// into a graph the FrameGraph owns (graph_, or the body of one of its WHILE nodes, which the node
// owns): the graph cudaStreamEndCapture returns is that one, and reset() destroys it with graph_.
// (Destroying it here too destroyed graph_ twice, or a WHILE node's body before its graph.)
void abandon_capture(cudaStream_t stream) {
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  if (cudaStreamIsCapturing(stream, &status) == cudaSuccess && status != cudaStreamCaptureStatusNone) {
    cudaGraph_t captured = nullptr;
    (void)cudaStreamEndCapture(stream, &captured);
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
    // graph_ itself comes back; an invalidated capture returns null, which must not replace
    // graph_ (reset() destroys it).
    cudaGraph_t captured = nullptr;
    cuda_check(cudaStreamEndCapture(stream, &captured), "capture of the frame end");

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
