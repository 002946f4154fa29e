// SPDX-License-Identifier: MIT
// The device side of a distributed world's rank (cuda_halo.cu): the buffers and kernels that
// stage what crosses to other ranks through the host. Nothing here talks to other ranks; the
// backend downloads what leaves, exchanges it over the RankTransport and uploads what arrives.
//   layers      each particle's cell layer along the slabs' axis (the host decides who owns it)
//   pack/keep   particles' arrays gathered by an index list: into a staging buffer (what leaves),
//               or back into the arrays' heads (what stays, in its order)
//   visit       the particles in the order of their sort keys (a stable 64-bit radix sort), the
//               order in which the grid's sort takes them
//   mark        after the sort: the ghost mask and each particle's new key (slot, place in it)
//   records     the density records of the owned particles beside another slab, and the
//               ghosts' update from their owners' records, checked by id
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/core/halo_records.h"
#include "device_array.h"
#include "device_neighbor_grid.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

// One array that travels with its particle: bytes per particle (a multiple of 4).
struct HaloArray {
  unsigned char* data;
  uint32_t bytes;
};

class DeviceHalo {
 public:
  explicit DeviceHalo(uint32_t capacity);

  // layers[i] for particles [0, n) into host_layers() (waits for the stream).
  void download_layers(const Float4* positions, uint32_t n, int axis, float inv_cell_size,
                       cudaStream_t stream);
  const int32_t* host_layers() const { return host_layers_.get(); }

  // Uploads idx[0, m) (ascending or not) as the device index list (waits for the stream).
  void upload_index(const uint32_t* idx, uint32_t m, cudaStream_t stream);
  // The arrays of the particles the index list names, one array after the other (each m x its
  // bytes), into pinned host memory (waits for the stream); returns it.
  const unsigned char* pack(const HaloArray* arrays, int count, uint32_t m, cudaStream_t stream);
  // Keeps the particles the index list names (m of them), in that order, at the arrays' heads.
  void keep(const HaloArray* arrays, int count, uint32_t m, cudaStream_t stream);
  // Writes particles [first, first + m) of each array from `bytes` (pack's layout; waits).
  void unpack(const HaloArray* arrays, int count, const unsigned char* bytes, uint32_t m, uint32_t first,
              cudaStream_t stream);

  // visit() = [0, n) in ascending key order, ties in storage order.
  void enqueue_visit(const uint64_t* keys, uint32_t n, cudaStream_t stream);
  const uint32_t* visit() const { return visit_.get(); }
  // After the grid's sort and cell starts: ghost[i] = (order[i] >= owned), keys[i] = the slot
  // and place of sorted particle i; order[0, n) goes to host_order() (read after the stream).
  void enqueue_mark(const DeviceNeighborGrid& grid, uint32_t n, uint32_t owned, uint32_t* ghost,
                    uint64_t* keys, cudaStream_t stream);
  const uint32_t* host_order() const { return host_order_.get(); }

  // The density records of the sorted particles the index list names (m), into pinned memory
  // (waits for the stream).
  const HaloDensityRecord* pack_density(const ParticleArrays& a, uint32_t m, cudaStream_t stream);
  // The ghosts the index list names take records[0, m) (enqueued; records are copied first).
  // A record whose id is not its ghost's raises mismatch(), which the host reads later.
  void enqueue_apply_density(const ParticleArrays& a, const HaloDensityRecord* records, uint32_t m,
                             cudaStream_t stream);
  uint32_t* mismatch_flag() const { return mismatch_.get(); }

  uint64_t bytes() const;

 private:
  void ensure_device(size_t bytes);
  void ensure_host(size_t bytes);

  uint32_t capacity_;
  DeviceArray<int32_t> layers_;
  DeviceArray<uint32_t> index_;
  DeviceArray<uint32_t> iota_, visit_;
  DeviceArray<uint64_t> sorted_keys_;
  DeviceArray<unsigned char> sort_temp_;
  size_t sort_temp_bytes_ = 0;
  DeviceArray<uint32_t> mismatch_;
  DeviceArray<unsigned char> staging_;  // grows on demand
  PinnedArray<int32_t> host_layers_;
  PinnedArray<uint32_t> host_index_;
  PinnedArray<uint32_t> host_order_;
  PinnedArray<unsigned char> host_staging_;  // grows on demand
  size_t host_staging_bytes_ = 0;
};

}  // namespace sph
