// SPDX-License-Identifier: MIT
// The device side of a distributed world's rank (cuda_halo.cu): the buffers and kernels that
// stage what crosses to other ranks through the host. Nothing here talks to other ranks; the
// backend downloads what leaves, exchanges it over the RankTransport and uploads what arrives.
//   lists       who goes where (core/slab_rules.h per particle, on the device): the migrants,
//               the ghosts, and after the sort what the ghosts' density records are; per rank,
//               in ascending order, by a stable radix sort on the destination. Only where each
//               rank's list starts reaches the host, and the bytes that leave.
//   pack/keep   particles' arrays gathered by an index list: into a staging buffer (what leaves),
//               or back into the arrays' heads (what stays, in its order)
//   visit       the particles in the order of their sort keys (a stable 64-bit radix sort), the
//               order in which the grid's sort takes them
//   mark        after the sort: the ghost mask and each particle's new key (slot, place in it)
//   records     the density records of the owned particles beside another slab, and the
//               ghosts' update from their owners' records, checked by id (and DFSPH's records and
//               its solves' error bins)
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include <vector>

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

// The most particles a rank's halo takes: its lists hold two entries a particle, counted in int.
constexpr uint32_t kMaxHaloCapacity = (1u << 30) - 1;

class DeviceHalo {
 public:
  // A rank of `ranks` ranks (their slabs' cuts come by set_cuts). Its set-up runs on `stream`
  // (the world's) and is waited for here.
  DeviceHalo(uint32_t capacity, int ranks, cudaStream_t stream);

  // The slabs' cuts (SlabDecomposition::cuts(), ranks - 1 of them) to the device (enqueued).
  void set_cuts(const std::vector<int32_t>& cuts, cudaStream_t stream);

  // Per-rank lists (device_halo_lists.cu): the device index list list() holds rank 0's list,
  // then rank 1's, ..., each ascending (the order of the host loops these replace, which the
  // receiver relies on); the host gets only where each list starts (pinned, read after the call
  // or, for enqueue_mark, after the stream).
  //   list_migrants  particles [0, n) by the rank that owns their sub-layer; starts[0, ranks] and
  //                  starts[ranks + 1] = n, with this rank's own list (what stays) last:
  //                  [starts[ranks], n). Waits for the stream.
  //   list_ghosts    particles [0, n) to the other ranks whose slabs meet their layer or those
  //                  beside (at most two: core/slab_rules.h; their layers are kept
  //                  for enqueue_mark); starts[0, ranks], starts[ranks] = the total. Waits.
  const uint32_t* list_migrants(const Float4* positions, uint32_t n, int axis, float inv_cell_size, int me,
                                cudaStream_t stream);
  const uint32_t* list_ghosts(const Float4* positions, uint32_t n, int axis, float inv_cell_size, int me,
                              cudaStream_t stream);
  const uint32_t* list() const { return list_.get(); }
  // Particles [first, first + m) are ghosts from rank `origin` (enqueued); spring ghosts from rank r
  // (cuda_halo_springs.cu) have origin ranks + r, and take no records.
  void enqueue_origin(uint32_t first, uint32_t m, uint32_t origin, cudaStream_t stream);

  // The arrays of the particles idx[0, m) names (a device list), one array after the other (each
  // m x its bytes), into pinned host memory (waits for the stream); returns it.
  const unsigned char* pack(const HaloArray* arrays, int count, const uint32_t* idx, uint32_t m,
                            cudaStream_t stream);
  // Keeps the particles idx[0, m) names (a device list), in that order, at the arrays' heads.
  void keep(const HaloArray* arrays, int count, const uint32_t* idx, uint32_t m, cudaStream_t stream);
  // Writes particles [first, first + m) of each array from `bytes` (pack's layout; waits).
  void unpack(const HaloArray* arrays, int count, const unsigned char* bytes, uint32_t m, uint32_t first,
              cudaStream_t stream);

  // visit() = [0, n) in ascending key order, ties in storage order.
  void enqueue_visit(const uint64_t* keys, uint32_t n, cudaStream_t stream);
  const uint32_t* visit() const { return visit_.get(); }
  // After the grid's sort and cell starts (enqueued): ghost[i] = (order[i] >= owned), keys[i] =
  // the slot and place of sorted particle i, and the lists of sorted positions, each ascending:
  // in list(), the owned particles beside rank d's slab (what d's ghosts take) for each d, then
  // the ghosts from rank r for each r; starts()[0, 2 ranks] (starts()[ranks] where the ghosts'
  // lists begin, starts()[2 ranks] their end); kept_list() the owned particles (kept_count()).
  void enqueue_mark(const DeviceNeighborGrid& grid, uint32_t n, uint32_t owned, int me, uint32_t* ghost,
                    uint64_t* keys, cudaStream_t stream);
  // After the stream, of the last enqueue_mark.
  const uint32_t* starts() const { return host_words_.get(); }
  uint32_t kept_count() const { return host_words_.get()[2 * ranks_ + 1]; }
  bool order_names_no_particle() const { return host_words_.get()[2 * ranks_ + 2] != 0; }
  const uint32_t* kept_list() const { return keep_.get(); }

  // The records (core/halo_records.h: HaloDensityRecord after the density pass, HaloNormalRecord
  // after the colour normals' pass) of the sorted particles idx[0, m) names (a device list), into
  // pinned memory (waits for the stream).
  template <class Record>
  const Record* pack_records(const ParticleArrays& a, const uint32_t* idx, uint32_t m, cudaStream_t stream);
  // The ghosts idx[0, m) names (a device list) take records[0, m) (enqueued; records are copied
  // first). A record whose id is not its ghost's raises mismatch(), which the host reads later.
  template <class Record>
  void enqueue_apply_records(const ParticleArrays& a, const uint32_t* idx, const Record* records, uint32_t m,
                             cudaStream_t stream);
  uint32_t* mismatch_flag() const { return mismatch_.get(); }

  // DFSPH's error words (dfsph_solver.h's kDfsphRankErrorWords: core/exact_float_sum.h's bins, int64
  // as two's complement, then the largest error's float bits): the rate pass adds the rank's own
  // particles' errors; the host reads them (waits). The conjugate gradients' use kDfsphRankCgWords
  // of them (their sums and maxima), reading `words`.
  unsigned long long* error_bins() const { return error_bins_.get(); }
  const int64_t* download_error_bins(cudaStream_t stream, uint32_t words);

  uint64_t bytes() const;

 private:
  void ensure_device(size_t bytes);
  void ensure_host(size_t bytes);
  // Sorts keys_in_[0, m) with values [0, m) of `values` (stable) into list_, and writes where
  // each key k <= last starts in the sorted keys to words_[k] (enqueued).
  void enqueue_lists(const uint32_t* values, uint32_t m, uint32_t last, cudaStream_t stream);
  void download_words(uint32_t count, cudaStream_t stream);
  size_t lists_temp_bytes(
      uint32_t items) const;  // CUB's temporary storage for enqueue_lists and the kept list

  uint32_t capacity_;
  int ranks_;
  int key_bits_;  // enough for every list key, 0 to 2 ranks
  DeviceArray<int32_t> cuts_;
  DeviceArray<int32_t> layers_;
  DeviceArray<uint32_t> origin_;
  DeviceArray<uint32_t> keys_in_, keys_out_, values_, list_;  // 2 x capacity: two entries a particle
  DeviceArray<uint32_t> keep_;
  DeviceArray<unsigned char> kept_flags_;
  DeviceArray<uint32_t> words_;  // list starts, the kept count, the order's check (host_words_)
  DeviceArray<unsigned char> lists_temp_;
  size_t lists_temp_bytes_ = 0;
  DeviceArray<uint32_t> iota_, visit_;
  DeviceArray<uint64_t> sorted_keys_;
  DeviceArray<unsigned char> sort_temp_;
  size_t sort_temp_bytes_ = 0;
  DeviceArray<uint32_t> mismatch_;
  DeviceArray<unsigned long long> error_bins_;
  PinnedArray<int64_t> host_error_bins_;
  DeviceArray<unsigned char> staging_;  // grows on demand
  PinnedArray<int32_t> host_cuts_;
  PinnedArray<uint32_t> host_words_;
  PinnedArray<unsigned char> host_staging_;  // grows on demand
  size_t host_staging_bytes_ = 0;
};

}  // namespace sph
