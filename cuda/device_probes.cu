// SPDX-License-Identifier: MIT
#include "device_particle_store.h"
#include "device_probes.h"
#include "kernel_launch.h"

namespace sph {
namespace {

// The probe that owns sample point q: the last whose first_point <= q (first points ascend).
__device__ uint32_t owner_of(const ProbeView* views, uint32_t count, uint32_t q) {
  uint32_t lo = 0, hi = count;
  while (hi - lo > 1) {
    const uint32_t mid = (lo + hi) / 2;
    if (views[mid].first_point <= q)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

__global__ void probe_points_kernel(DeviceProbes probes, GridView grid, const Float4* positions,
                                    const Float4* velocities) {
  const uint32_t q = blockIdx.x * blockDim.x + threadIdx.x;
  if (q >= probes.point_count) return;
  const ProbeView p = probes.views[owner_of(probes.views, probes.probe_count, q)];
  probes.points[q] =
      gather_probe_point(probes.constants, grid, positions, velocities, probe_point(p, q - p.first_point));
}

// One thread per probe: its points in order, then its sample into the frame's sums.
__global__ void probe_sums_kernel(DeviceProbes probes, const FrameState* state) {
  const uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= probes.probe_count) return;
  const ProbeView p = probes.views[k];
  ProbeGather g = zero_probe_gather();
  for (uint32_t q = 0; q < p.point_count; ++q) g = g + probes.points[p.first_point + q];
  add_probe_sample(probes.sums[k], p, probe_sample(probes.constants, p, g), state->clock.time.dt);
}

}  // namespace

DeviceProbes DeviceProbeBuffers::upload(const SceneFrame& scene, const ProbeConstants& constants,
                                        cudaStream_t stream) {
  DeviceProbes d;
  if (scene.probes.empty()) return d;
  const size_t probes = scene.probes.size();
  // A new generation before any buffer is freed, so that a failure below leaves it changed too.
  if (views_.size() < probes || sums_.size() < probes || output_slots_ < probes ||
      points_.size() < scene.probe_points)
    generation_ = next_buffer_generation();
  if (views_.size() < probes) views_.allocate(probes, "device probe views");
  if (sums_.size() < probes) sums_.allocate(probes, "the probes' frame sums");
  if (output_slots_ < probes) {
    output_slots_ = 0;  // allocate() frees the old copy first: a failure leaves none
    output_.allocate(probes, "the probes' host copy");
    output_slots_ = probes;
  }
  if (points_.size() < scene.probe_points) points_.allocate(scene.probe_points, "the probes' sample points");
  host_views_ = scene.probes;
  cuda_check(cudaMemcpyAsync(views_.get(), host_views_.data(), sizeof(ProbeView) * probes,
                             cudaMemcpyHostToDevice, stream),
             "device probe views");
  d.views = views_.get();
  d.points = points_.get();
  d.sums = sums_.get();
  d.output = output_.get();
  d.probe_count = static_cast<uint32_t>(probes);
  d.point_count = scene.probe_points;
  d.constants = constants;
  d.generation = generation_;
  return d;
}

void enqueue_probes_begin(const DeviceProbes& probes, cudaStream_t stream) {
  cuda_check(cudaMemsetAsync(probes.sums, 0, sizeof(ProbeSums) * probes.probe_count, stream),
             "zeroing of the probes");
}

void enqueue_probes_end(const DeviceProbes& probes, cudaStream_t stream) {
  cuda_check(cudaMemcpyAsync(probes.output, probes.sums, sizeof(ProbeSums) * probes.probe_count,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the probes");
}

void enqueue_probe_points(const DeviceProbes& probes, const GridView& grid, const ParticleArrays& a,
                          cudaStream_t stream) {
  probe_points_kernel<<<blocks_for(probes.point_count, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      probes, grid, a.sorted_position, a.sorted_velocity);
  check_launch("probe_points_kernel");
}

void enqueue_probe_sums(const DeviceProbes& probes, const FrameState* state, cudaStream_t stream) {
  probe_sums_kernel<<<blocks_for(probes.probe_count, 64), 64, 0, stream>>>(probes, state);
  check_launch("probe_sums_kernel");
}

void enqueue_probe_samples(const DeviceProbes& probes, const GridView& grid, const ParticleArrays& a,
                           const FrameState* state, cudaStream_t stream) {
  enqueue_probe_points(probes, grid, a, stream);
  enqueue_probe_sums(probes, state, stream);
}

}  // namespace sph
