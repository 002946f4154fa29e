// SPDX-License-Identifier: MIT
// Probes and gauges on the device: the frame's probe views, the sums of each sample point and
// each probe's frame sums (the twin of src/cpu/cpu_probes.cpp; the physics is
// src/physics/probe_sampling.h). After a substep's density pass one kernel gathers the SPH
// interpolant at every sample point (a thread per point, the grid's fixed walk order), and a
// second adds each probe's points in order and its sample, weighted by the substep's dt from the
// device clock, into the frame's sums. The sums are zeroed at the frame's begin and copied to
// pinned host memory at its end, inside the graph: no host round trip per substep.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <vector>

#include "../src/core/scene_frame.h"
#include "../src/physics/probe_sampling.h"
#include "device_array.h"
#include "frame_state.cuh"

namespace sph {

struct ParticleArrays;

// What the passes see (all null and zero when the frame has no probe).
struct DeviceProbes {
  const ProbeView* views = nullptr;  // device, per probe
  ProbeGather* points = nullptr;     // device, per sample point
  ProbeSums* sums = nullptr;         // device, per probe: the frame's samples
  ProbeSums* output = nullptr;       // pinned host, receives sums at the frame's end
  uint32_t probe_count = 0;
  uint32_t point_count = 0;
  ProbeConstants constants{};
  uint64_t generation = 0;  // host only: changes with every reallocation (next_buffer_generation)

  bool on() const { return probe_count > 0; }
};

// The buffers, grown (never shrunk) to the scene's probes and points.
class DeviceProbeBuffers {
 public:
  // Copies the frame's probe views to the device on `stream`.
  DeviceProbes upload(const SceneFrame& scene, const ProbeConstants& constants, cudaStream_t stream);
  uint64_t bytes() const { return views_.bytes() + points_.bytes() + sums_.bytes(); }
  // The views of the last upload, on the host (a distributed rank picks each point's owner by them).
  const HostVector<ProbeView>& host_views() const { return host_views_; }

 private:
  DeviceArray<ProbeView> views_;
  DeviceArray<ProbeGather> points_;
  DeviceArray<ProbeSums> sums_;
  PinnedArray<ProbeSums> output_;
  size_t output_slots_ = 0;
  uint64_t generation_ = next_buffer_generation();
  HostVector<ProbeView> host_views_;
};

// The frame's sums to zero (frame begin) / to the pinned output (frame end).
void enqueue_probes_begin(const DeviceProbes& probes, cudaStream_t stream);
void enqueue_probes_end(const DeviceProbes& probes, cudaStream_t stream);

// One substep's samples, after its density pass (the sorted records and the grid): the points'
// gathers (enqueue_probe_points), then each probe's sample into the frame's sums
// (enqueue_probe_sums); a distributed rank takes each point's owner's gather between the two.
void enqueue_probe_samples(const DeviceProbes& probes, const GridView& grid, const ParticleArrays& a,
                           const FrameState* state, cudaStream_t stream);
void enqueue_probe_points(const DeviceProbes& probes, const GridView& grid, const ParticleArrays& a,
                          cudaStream_t stream);
void enqueue_probe_sums(const DeviceProbes& probes, const FrameState* state, cudaStream_t stream);

}  // namespace sph
