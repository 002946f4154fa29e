// SPDX-License-Identifier: MIT
// Sinks on the device: after a substep, every particle inside a sink (or outside its bounds)
// is removed with a stable compaction, so the survivors keep their relative order exactly as
// in the CPU backend's apply_sinks; the removed ids come out in the same order, each with the
// index of the first sink that removed it. The buffers are allocated on a world's first frame
// with sinks, for its capacity.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/host_memory.h"
#include "../src/physics/sink_region.h"
#include "device_array.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

class DeviceSinkCompactor {
 public:
  // Allocates the buffers for `capacity` particles (again when a grown world asks for more;
  // throws OUT_OF_DEVICE_MEMORY), with room
  // for the widest of the store's carried arrays.
  void reserve(uint32_t capacity, const DeviceParticleStore& store);
  bool ready() const { return capacity_ != 0; }

  // Tests particles [0, n) of a.position against the sinks and counts the survivors into
  // kept_device().
  void enqueue_flag(const SinkView* sinks, uint32_t sink_count, const ParticleArrays& a, uint32_t n,
                    FrameState* state, cudaStream_t stream);
  const uint32_t* kept_device() const { return kept_.get(); }

  // Compacts the state (position, velocity, id, density, the methods' carried arrays; and
  // counts, when given, in place) to the `kept` survivors, and writes the n - kept removed ids and
  // their sink indices. Uses the sorted working copy as scratch (dead between substeps). A
  // carried array whose elements hold particle indices is its method's to compact (springs).
  void enqueue_compact(const DeviceParticleStore& store, uint32_t n, uint32_t kept, uint32_t* counts,
                       cudaStream_t stream);
  const uint32_t* removed_ids() const { return removed_id_.get(); }
  const uint32_t* removed_sinks() const { return removed_sink_.get(); }
  // After enqueue_compact: waits for the stream, appends the `removed` ids to removed_ids (in the
  // compaction's order) and counts them per sink into removed_by_sink (one entry per sink).
  void take_removed(uint32_t removed, HostVector<uint32_t>& removed_ids,
                    HostVector<uint32_t>& removed_by_sink, cudaStream_t stream);
  // A side array of `capacity` entries for the neighbour counts of the last density pass.
  uint32_t* counts() const { return counts_.get(); }

  uint64_t bytes() const {
    return keep_.bytes() + scan_.bytes() + sink_of_.bytes() + removed_id_.bytes() + removed_sink_.bytes() +
           counts_.bytes() + counts_out_.bytes() + words_out_.bytes() + kept_.bytes() + temp_.bytes();
  }

 private:
  uint32_t capacity_ = 0;
  DeviceArray<uint32_t> keep_, scan_, sink_of_, removed_id_, removed_sink_, counts_, counts_out_;
  DeviceArray<uint32_t> words_out_;  // the compacted densities, then each carried array in turn
  uint32_t words_per_particle_ = 1;  // of words_out_
  DeviceArray<uint32_t> kept_;
  DeviceArray<unsigned char> temp_;
  size_t temp_bytes_ = 0;
  HostVector<uint32_t> host_ids_, host_sinks_;  // take_removed's staging, kept between frames
};

}  // namespace sph
