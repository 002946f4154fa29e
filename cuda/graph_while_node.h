// SPDX-License-Identifier: MIT
// A conditional WHILE node added to the graph a stream is being captured into, its body captured
// from a callable. The frame graph's substep loop (frame_graph.cu) and DFSPH's solve loops
// (dfsph_solve_loop.cuh) both need it: CUDA cannot capture a conditional node, so the capture is
// ended, the node added after what was captured so far, its body captured into the node's own
// graph, and the capture resumed with the node as its only dependency.
#pragma once

#include <cuda_runtime.h>

#include "../src/core/host_memory.h"
#include "cuda_status.h"

namespace sph {

template <class Body>
void capture_while_node(cudaGraphConditionalHandle handle, cudaStream_t stream, Body&& body) {
  constexpr cudaStreamCaptureMode kCaptureMode = cudaStreamCaptureModeThreadLocal;
  cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
  cudaGraph_t graph = nullptr;
  const cudaGraphNode_t* leaves = nullptr;
  size_t leaf_count = 0;
  cuda_check(cudaStreamGetCaptureInfo(stream, &status, nullptr, &graph, &leaves, nullptr, &leaf_count),
             "cudaStreamGetCaptureInfo");
  const HostVector<cudaGraphNode_t> after(leaves, leaves + leaf_count);  // (the capture's end frees leaves)
  cuda_check(cudaStreamEndCapture(stream, &graph), "capture before a WHILE node");
  cudaGraphNodeParams params = {};
  params.type = cudaGraphNodeTypeConditional;
  params.conditional.handle = handle;
  params.conditional.type = cudaGraphCondTypeWhile;
  params.conditional.size = 1;
  cudaGraphNode_t loop = nullptr;
  cuda_check(cudaGraphAddNode(&loop, graph, after.data(), nullptr, after.size(), &params),
             "conditional WHILE node");
  cudaGraph_t body_graph = params.conditional.phGraph_out[0];
  cuda_check(cudaStreamBeginCaptureToGraph(stream, body_graph, nullptr, nullptr, 0, kCaptureMode),
             "capture of a WHILE node's body");
  body();
  cuda_check(cudaStreamEndCapture(stream, &body_graph), "capture of a WHILE node's body");
  cuda_check(cudaStreamBeginCaptureToGraph(stream, graph, &loop, nullptr, 1, kCaptureMode),
             "capture after a WHILE node");
}

}  // namespace sph
