// SPDX-License-Identifier: MIT
#include <vector>

#include "frame_graph.h"

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

    // 1. begin segment, captured into the frame graph; remember its last nodes.
    cuda_check(cudaStreamBeginCaptureToGraph(stream, graph_, nullptr, nullptr, 0, kCaptureMode),
               "capture of the frame begin");
    enqueue_frame_begin(setup, buffers, cond, stream);
    cudaStreamCaptureStatus status;
    const cudaGraphNode_t* leaves = nullptr;
    size_t leaf_count = 0;
    cuda_check(cudaStreamGetCaptureInfo(stream, &status, nullptr, nullptr, &leaves, nullptr, &leaf_count),
               "cudaStreamGetCaptureInfo");
    const HostVector<cudaGraphNode_t> begin_leaves(leaves, leaves + leaf_count);
    cuda_check(cudaStreamEndCapture(stream, &graph_), "capture of the frame begin");

    // 2. the WHILE node; its body is one substep.
    cudaGraphNodeParams params = {};
    params.type = cudaGraphNodeTypeConditional;
    params.conditional.handle = cond.handle;
    params.conditional.type = cudaGraphCondTypeWhile;
    params.conditional.size = 1;
    cudaGraphNode_t loop = nullptr;
    cuda_check(cudaGraphAddNode(&loop, graph_, begin_leaves.data(), nullptr, begin_leaves.size(), &params),
               "conditional WHILE node");
    cudaGraph_t body = params.conditional.phGraph_out[0];
    cuda_check(cudaStreamBeginCaptureToGraph(stream, body, nullptr, nullptr, 0, kCaptureMode),
               "capture of the substep");
    enqueue_substep(setup, buffers, cond, stream);
    cuda_check(cudaStreamEndCapture(stream, &body), "capture of the substep");

    // 3. end segment after the loop.
    cuda_check(cudaStreamBeginCaptureToGraph(stream, graph_, &loop, nullptr, 1, kCaptureMode),
               "capture of the frame end");
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
