// SPDX-License-Identifier: MIT
// A distributed CUDA rank's per-rank lists (device_halo.h): who migrates, who goes out as a
// ghost, and after the sort which sorted particles send and take density records. The host
// loops these replace listed, for each destination, its particles in ascending order, and the
// receiving rank reads what arrives in that order; here each particle (or sorted place) writes
// one or two (destination, index) entries in index order, and a stable radix sort on the
// destination groups them without reordering any destination's entries. The host gets the
// lists' starts (a lower bound per destination in the sorted keys) and, from pack, the bytes.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>

#include <algorithm>
#include <string>

#include "../src/core/slab_rules.h"
#include "device_halo.h"
#include "device_lower_bound.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

// Migration: key = the owner of the particle's sub-layer, this rank's own (what stays) last.
__global__ void migrant_keys_kernel(const Float4* __restrict__ positions, uint32_t n, int axis, float inv,
                                    const int32_t* __restrict__ cuts, int ranks, int me,
                                    uint32_t* __restrict__ keys) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const Float4 p = positions[i];
  const int owner = slab_owner(cuts, ranks - 1, slab_position(p.x, p.y, p.z, axis, inv));
  keys[i] = owner == me ? static_cast<uint32_t>(ranks) : static_cast<uint32_t>(owner);
}

// Ghosts: entries 2i and 2i + 1 name particle i for the other ranks whose slabs meet its layer or
// those beside (slab_rules.h: at most two), in rank order
// (key `ranks`: none).
__global__ void ghost_keys_kernel(const Float4* __restrict__ positions, uint32_t n, int axis, float inv,
                                  const int32_t* __restrict__ cuts, int ranks, int me,
                                  int32_t* __restrict__ layers, uint32_t* __restrict__ keys,
                                  uint32_t* __restrict__ values) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const Float4 p = positions[i];
  const int32_t layer = slab_layer(p.x, p.y, p.z, axis, inv);
  layers[i] = layer;
  int dst[2];
  const int c = slab_ghost_destinations(cuts, ranks - 1, layer, me, dst);
  const uint32_t none = static_cast<uint32_t>(ranks);
  keys[2 * i] = c > 0 ? static_cast<uint32_t>(dst[0]) : none;
  keys[2 * i + 1] = c > 1 ? static_cast<uint32_t>(dst[1]) : none;
  values[2 * i] = i;
  values[2 * i + 1] = i;
}

// After the sort, sorted place i of particle order[i]: the ghost mask and new sort key (slot,
// place in it), whether it is owned (the kept list), and its entries: an owned particle beside
// rank d's slab under key d (d's ghosts read its density record), a ghost from rank r under key
// ranks + r (it takes a record from r); key 2 ranks: none (also a spring ghost's, whose origin is
// ranks + r: cuda_halo_springs.cu). An order past the particles raises
// the check word and lists nothing.
__global__ void mark_kernel(const uint32_t* __restrict__ order, const uint32_t* __restrict__ sorted_slots,
                            const uint32_t* __restrict__ cell_start, uint32_t n, uint32_t owned,
                            const int32_t* __restrict__ cuts, int ranks, int me,
                            const int32_t* __restrict__ layers, const uint32_t* __restrict__ origin,
                            uint32_t* __restrict__ ghost, uint64_t* __restrict__ sort_keys,
                            unsigned char* __restrict__ kept, uint32_t* __restrict__ keys,
                            uint32_t* __restrict__ values, uint32_t* __restrict__ bad_order) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const uint32_t k = order[i];
  ghost[i] = k >= owned ? 1u : 0u;
  const uint32_t slot = sorted_slots[i];
  sort_keys[i] = (static_cast<uint64_t>(slot) << 32) | (i - cell_start[slot]);
  const uint32_t none = 2u * static_cast<uint32_t>(ranks);
  uint32_t first = none, second = none;
  if (k >= n) {
    atomicOr(bad_order, 1u);
  } else if (k < owned) {
    int dst[2];
    const int c = slab_ghost_destinations(cuts, ranks - 1, layers[k], me, dst);
    if (c > 0) first = static_cast<uint32_t>(dst[0]);
    if (c > 1) second = static_cast<uint32_t>(dst[1]);
  } else if (origin[k] < static_cast<uint32_t>(ranks)) {
    first = static_cast<uint32_t>(ranks) + origin[k];
  }  // (else a spring ghost: in no neighbour walk of an owned particle, it takes no record)
  kept[i] = k < owned ? 1 : 0;
  keys[2 * i] = first;
  keys[2 * i + 1] = second;
  values[2 * i] = i;
  values[2 * i + 1] = i;
}

// starts[k] = the first place in sorted[0, m) whose key is >= k, for k in [0, last].
__global__ void list_starts_kernel(const uint32_t* __restrict__ sorted, uint32_t m, uint32_t last,
                                   uint32_t* __restrict__ starts) {
  const uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k > last) return;
  starts[k] = lower_bound_u32(sorted, 0, m, k);
}

__global__ void fill_kernel(uint32_t* __restrict__ v, uint32_t m, uint32_t value) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < m) v[i] = value;
}

}  // namespace

size_t DeviceHalo::lists_temp_bytes(uint32_t items) const {
  size_t sort = 0, select = 0;
  cuda_check(
      cub::DeviceRadixSort::SortPairs(nullptr, sort, static_cast<const uint32_t*>(nullptr),
                                      static_cast<uint32_t*>(nullptr), static_cast<const uint32_t*>(nullptr),
                                      static_cast<uint32_t*>(nullptr), static_cast<int>(items), 0, key_bits_),
      "halo list sort size query");
  cuda_check(
      cub::DeviceSelect::Flagged(nullptr, select, static_cast<const uint32_t*>(nullptr),
                                 static_cast<const unsigned char*>(nullptr), static_cast<uint32_t*>(nullptr),
                                 static_cast<uint32_t*>(nullptr), static_cast<int>(items / 2)),
      "halo kept list size query");
  return std::max(sort, select);
}

void DeviceHalo::set_cuts(const std::vector<int32_t>& cuts, cudaStream_t stream) {
  if (cuts.size() != static_cast<size_t>(ranks_ - 1))
    throw Error(Status::Internal, "halo: cuts for another number of ranks");
  if (cuts.empty()) return;
  std::copy(cuts.begin(), cuts.end(), host_cuts_.get());
  // (The pinned cuts are not written again before the stream's next wait: list_migrants.)
  cuda_check(cudaMemcpyAsync(cuts_.get(), host_cuts_.get(), sizeof(int32_t) * cuts.size(),
                             cudaMemcpyHostToDevice, stream),
             "copy of the slab cuts");
}

void DeviceHalo::enqueue_lists(const uint32_t* values, uint32_t m, uint32_t last, cudaStream_t stream) {
  size_t bytes = 0;
  cuda_check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, keys_in_.get(), keys_out_.get(), values,
                                             list_.get(), static_cast<int>(m), 0, key_bits_, stream),
             "halo list sort size query");
  if (bytes > lists_temp_bytes_) throw Error(Status::Internal, "halo: the list sort outgrew its storage");
  cuda_check(cub::DeviceRadixSort::SortPairs(lists_temp_.get(), bytes, keys_in_.get(), keys_out_.get(),
                                             values, list_.get(), static_cast<int>(m), 0, key_bits_, stream),
             "halo list sort");
  list_starts_kernel<<<blocks_for(last + 1, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      keys_out_.get(), m, last, words_.get());
  check_launch("list_starts_kernel");
}

void DeviceHalo::download_words(uint32_t count, cudaStream_t stream) {
  cuda_check(cudaMemcpyAsync(host_words_.get(), words_.get(), sizeof(uint32_t) * count,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the halo list starts");
}

const uint32_t* DeviceHalo::list_migrants(const Float4* positions, uint32_t n, int axis, float inv_cell_size,
                                          int me, cudaStream_t stream) {
  if (n > capacity_) throw Error(Status::Internal, "halo: more particles than the capacity");
  const uint32_t last = static_cast<uint32_t>(ranks_) + 1u;
  if (n == 0) {
    std::fill(host_words_.get(), host_words_.get() + last + 1, 0u);
    return host_words_.get();
  }
  migrant_keys_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      positions, n, axis, inv_cell_size, cuts_.get(), ranks_, me, keys_in_.get());
  check_launch("migrant_keys_kernel");
  enqueue_lists(iota_.get(), n, last, stream);
  download_words(last + 1, stream);
  cuda_check(cudaStreamSynchronize(stream), "halo migrant lists");
  return host_words_.get();
}

const uint32_t* DeviceHalo::list_ghosts(const Float4* positions, uint32_t n, int axis, float inv_cell_size,
                                        int me, cudaStream_t stream) {
  if (n > capacity_) throw Error(Status::Internal, "halo: more particles than the capacity");
  const uint32_t last = static_cast<uint32_t>(ranks_);
  if (n == 0) {
    std::fill(host_words_.get(), host_words_.get() + last + 1, 0u);
    return host_words_.get();
  }
  ghost_keys_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      positions, n, axis, inv_cell_size, cuts_.get(), ranks_, me, layers_.get(), keys_in_.get(),
      values_.get());
  check_launch("ghost_keys_kernel");
  enqueue_lists(values_.get(), 2 * n, last, stream);
  download_words(last + 1, stream);
  cuda_check(cudaStreamSynchronize(stream), "halo ghost lists");
  return host_words_.get();
}

void DeviceHalo::enqueue_origin(uint32_t first, uint32_t m, uint32_t origin, cudaStream_t stream) {
  if (m == 0) return;
  if (static_cast<uint64_t>(first) + m > capacity_)
    throw Error(Status::Internal, "halo: ghosts past the capacity");
  fill_kernel<<<blocks_for(m, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(origin_.get() + first, m,
                                                                                  origin);
  check_launch("fill_kernel");
}

void DeviceHalo::enqueue_mark(const DeviceNeighborGrid& grid, uint32_t n, uint32_t owned, int me,
                              uint32_t* ghost, uint64_t* keys, cudaStream_t stream) {
  if (n > capacity_) throw Error(Status::Internal, "halo: more particles than the capacity");
  const uint32_t last = 2u * static_cast<uint32_t>(ranks_);
  const uint32_t words = last + 3u;
  if (n == 0) {
    std::fill(host_words_.get(), host_words_.get() + words, 0u);
    return;
  }
  uint32_t* bad_order = words_.get() + last + 2;
  cuda_check(cudaMemsetAsync(bad_order, 0, sizeof(uint32_t), stream), "halo order check reset");
  const CrowdGuard g = grid.crowd_guard();
  mark_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      grid.order(), g.sorted_keys, g.cell_start, n, owned, cuts_.get(), ranks_, me, layers_.get(),
      origin_.get(), ghost, keys, kept_flags_.get(), keys_in_.get(), values_.get(), bad_order);
  check_launch("mark_kernel");
  // (The order lives in the sort's scratch, which the density pass overwrites: read here.)
  enqueue_lists(values_.get(), 2 * n, last, stream);
  size_t bytes = 0;
  cuda_check(cub::DeviceSelect::Flagged(nullptr, bytes, iota_.get(), kept_flags_.get(), keep_.get(),
                                        words_.get() + last + 1, static_cast<int>(n), stream),
             "halo kept list size query");
  if (bytes > lists_temp_bytes_) throw Error(Status::Internal, "halo: the kept list outgrew its storage");
  cuda_check(cub::DeviceSelect::Flagged(lists_temp_.get(), bytes, iota_.get(), kept_flags_.get(), keep_.get(),
                                        words_.get() + last + 1, static_cast<int>(n), stream),
             "halo kept list");
  download_words(words, stream);
}

}  // namespace sph
