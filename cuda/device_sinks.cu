// SPDX-License-Identifier: MIT
#include <cub/device/device_scan.cuh>

#include "device_sinks.h"
#include "device_springs.h"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr uint32_t kKept = 0xffffffffu;

__global__ void sink_flag_kernel(const SinkView* __restrict__ sinks, uint32_t sink_count,
                                 const Float4* __restrict__ position, uint32_t n, uint32_t* keep,
                                 uint32_t* sink_of, FrameState* state) {
  mark_stage(state, kStageEmit);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const Vec3 x = xyz(position[i]);
  uint32_t by = kKept;
  for (uint32_t s = 0; s < sink_count && by == kKept; ++s)
    if (sink_removes(sinks[s], x)) by = s;
  sink_of[i] = by;
  keep[i] = by == kKept ? 1u : 0u;
}

__global__ void kept_total_kernel(const uint32_t* keep, const uint32_t* scan, uint32_t n, uint32_t* kept) {
  *kept = n == 0 ? 0u : scan[n - 1] + keep[n - 1];
}

// Survivor i goes to scan[i]; the r-th removed particle (r = i - scan[i]) to the removed lists.
__global__ void sink_scatter_kernel(ParticleArrays a, uint32_t n, const uint32_t* __restrict__ keep,
                                    const uint32_t* __restrict__ scan, const uint32_t* __restrict__ sink_of,
                                    const uint32_t* __restrict__ counts, uint32_t* counts_out,
                                    float* density_out, uint32_t* removed_id, uint32_t* removed_sink) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const uint32_t dst = scan[i];
  if (keep[i]) {
    a.sorted_position[dst] = a.position[i];
    a.sorted_velocity[dst] = a.velocity[i];
    a.sorted_id[dst] = a.id[i];
    density_out[dst] = a.density[i];
    if (counts) counts_out[dst] = counts[i];
  } else {
    const uint32_t r = i - dst;
    removed_id[r] = a.id[i];
    removed_sink[r] = sink_of[i];
  }
}

// A carried array of `words` 32-bit words per particle: survivor i's words to place scan[i].
__global__ void compact_words_kernel(const uint32_t* __restrict__ in, uint32_t words, uint32_t n,
                                     const uint32_t* __restrict__ keep, const uint32_t* __restrict__ scan,
                                     uint32_t* out) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || !keep[i]) return;
  for (uint32_t w = 0; w < words; ++w)
    out[static_cast<uint64_t>(scan[i]) * words + w] = in[static_cast<uint64_t>(i) * words + w];
}

// The carried arrays this compaction moves as plain words (elements holding indices are their
// method's), and their words per particle.
bool compacted_as_words(const DeviceMethodArray& m) {
  return m.spec.role == ParticleArrayRole::Carried && m.spec.elements_per_particle != 0 &&
         !m.spec.rewrite_indices;
}
uint32_t words_of(const DeviceMethodArray& m) {
  return m.spec.element_size / 4u * m.spec.elements_per_particle;
}

template <class T>
void copy_back(T* dst, const T* src, uint32_t n, cudaStream_t stream, const char* what) {
  if (n == 0) return;
  cuda_check(cudaMemcpyAsync(dst, src, sizeof(T) * n, cudaMemcpyDeviceToDevice, stream), what);
}

}  // namespace

void DeviceSinkCompactor::reserve(uint32_t capacity, const DeviceParticleStore& store) {
  if (capacity <= capacity_) return;
  capacity_ = 0;  // a failure half-way leaves the compactor unreserved, so the next frame retries
  const size_t n = capacity;
  words_per_particle_ = 1;  // the densities
  for (const auto& m : store.method_arrays())
    if (compacted_as_words(*m) && words_of(*m) > words_per_particle_) words_per_particle_ = words_of(*m);
  keep_.allocate(n, "sink flags");
  scan_.allocate(n, "sink scan");
  sink_of_.allocate(n, "sink indices");
  removed_id_.allocate(n, "removed ids");
  removed_sink_.allocate(n, "removed sink indices");
  counts_.allocate(n, "sink neighbour counts");
  counts_out_.allocate(n, "sink neighbour counts (compacted)");
  words_out_.allocate(n * words_per_particle_, "sink compaction output");
  kept_.allocate(1, "sink survivor count");
  cuda_check(
      cub::DeviceScan::ExclusiveSum(nullptr, temp_bytes_, keep_.get(), scan_.get(), static_cast<int>(n)),
      "sink scan size");
  temp_.allocate(temp_bytes_ == 0 ? 1 : temp_bytes_, "sink scan storage");
  capacity_ = capacity;
}

void DeviceSinkCompactor::enqueue_flag(const SinkView* sinks, uint32_t sink_count, const ParticleArrays& a,
                                       uint32_t n, FrameState* state, cudaStream_t stream) {
  sink_flag_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      sinks, sink_count, a.position, n, keep_.get(), sink_of_.get(), state);
  check_launch("sink_flag_kernel");
  if (n > 0) {
    size_t bytes = temp_bytes_;
    cuda_check(cub::DeviceScan::ExclusiveSum(temp_.get(), bytes, keep_.get(), scan_.get(),
                                             static_cast<int>(n), stream),
               "sink scan");
  }
  kept_total_kernel<<<1, 1, 0, stream>>>(keep_.get(), scan_.get(), n, kept_.get());
  check_launch("kept_total_kernel");
}

void DeviceSinkCompactor::enqueue_compact(const DeviceParticleStore& store, uint32_t n, uint32_t kept,
                                          uint32_t* counts, cudaStream_t stream) {
  const ParticleArrays& a = store.arrays();
  float* density_out = reinterpret_cast<float*>(words_out_.get());
  const unsigned blocks = blocks_for(n, kDefaultBlockSize);
  sink_scatter_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(
      a, n, keep_.get(), scan_.get(), sink_of_.get(), counts, counts_out_.get(), density_out,
      removed_id_.get(), removed_sink_.get());
  check_launch("sink_scatter_kernel");
  copy_back(a.position, a.sorted_position, kept, stream, "compaction of positions");
  copy_back(a.velocity, a.sorted_velocity, kept, stream, "compaction of velocities");
  copy_back(a.id, a.sorted_id, kept, stream, "compaction of ids");
  copy_back(a.density, density_out, kept, stream, "compaction of densities");
  if (counts) copy_back(counts, counts_out_.get(), kept, stream, "compaction of neighbour counts");
  // SPH_FEATURE_SPRINGS; a distributed rank's lists (its ghost mask: a rank) name partners by id.
  if (a.springs)
    enqueue_spring_compact(a, n, kept, keep_.get(), scan_.get(), a.halo_ghost != nullptr, stream);
  // The methods' other carried arrays (the normalised density's factors, say), one at a time
  // through the output buffer, in stream order after the densities.
  for (const auto& m : store.method_arrays()) {
    if (!compacted_as_words(*m)) continue;
    uint32_t* words = reinterpret_cast<uint32_t*>(m->side[0].get());
    compact_words_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(words, words_of(*m), n, keep_.get(),
                                                                   scan_.get(), words_out_.get());
    check_launch("compact_words_kernel");
    copy_back(words, words_out_.get(), kept * words_of(*m), stream, m->spec.name);
  }
}

void DeviceSinkCompactor::take_removed(uint32_t removed, HostVector<uint32_t>& removed_ids,
                                       HostVector<uint32_t>& removed_by_sink, cudaStream_t stream) {
  host_ids_.resize(removed);
  host_sinks_.resize(removed);
  cuda_check(cudaMemcpyAsync(host_ids_.data(), removed_id_.get(), sizeof(uint32_t) * removed,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the removed ids");
  cuda_check(cudaMemcpyAsync(host_sinks_.data(), removed_sink_.get(), sizeof(uint32_t) * removed,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the removed ids' sinks");
  cuda_check(cudaStreamSynchronize(stream), "sinks");
  removed_ids.insert(removed_ids.end(), host_ids_.begin(), host_ids_.end());
  for (uint32_t k : host_sinks_) ++removed_by_sink[k];
}

}  // namespace sph
