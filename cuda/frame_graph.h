// SPDX-License-Identifier: MIT
// One frame as one CUDA graph: the begin segment, a conditional WHILE node whose body is one
// substep (captured from the stream, CUB's sort included) and whose condition the
// end-of-substep kernel sets, then the end segment. Launching it runs the whole adaptive frame
// on the device with no host involvement until the final FrameState copy.
#pragma once

#include <cuda_runtime.h>

#include "substep_pipeline.h"

namespace sph {

class FrameGraph {
 public:
  FrameGraph() = default;
  ~FrameGraph() { reset(); }
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Captures and instantiates the graph for this setup; throws on failure (nothing kept).
  void build(const PipelineSetup& setup, const PipelineBuffers& buffers, cudaStream_t stream);
  void launch(cudaStream_t stream) const;
  bool ready() const { return exec_ != nullptr; }
  void reset() noexcept;

 private:
  cudaGraph_t graph_ = nullptr;
  cudaGraphExec_t exec_ = nullptr;
};

}  // namespace sph
