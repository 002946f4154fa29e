// SPDX-License-Identifier: MIT
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>

#include <algorithm>
#include <cstring>

#include "device_halo_springs.h"
#include "device_iota.h"
#include "device_lower_bound.cuh"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr uint32_t kSlots = kSpringSlots;

// CUB's item counts, 64-bit: the selections run over kSlots (16) entries a particle, past INT_MAX
// above 134,217,727 particles on a rank (an int count overflowed there); CUB takes int64 counts
// (DeviceSelect's are int64 in CCCL 3; DeviceRadixSort picks its offsets from the count's type).
// The table's sorts stay int: n <= the capacity <= 2^30 (sph_world_def).
using ItemCount = int64_t;
ItemCount entries_of(uint64_t particles) { return static_cast<ItemCount>(particles * kSlots); }

// The index of the particle whose id is `id` in the table (ids ascending, each once), or kNoSpring.
__device__ uint32_t find_index(const uint32_t* __restrict__ ids, const uint32_t* __restrict__ idx, uint32_t n,
                               uint32_t id) {
  const uint32_t at = lower_bound_u32(ids, 0, n, id);
  return at < n && ids[at] == id ? idx[at] : kNoSpring;
}

__global__ void index_owned_kernel(SpringList* __restrict__ lists, uint32_t owned,
                                   const uint32_t* __restrict__ ids, const uint32_t* __restrict__ idx,
                                   uint32_t n, uint32_t* __restrict__ missing) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= owned) return;
  SpringList l = lists[i];
  uint32_t* mine = missing + static_cast<uint64_t>(i) * kSlots;
  for (uint32_t k = 0; k < kSlots; ++k) {
    const uint32_t p = l.partner[k];
    uint32_t waits = kNoSpring;
    if (p != kNoSpring) {
      const uint32_t j = find_index(ids, idx, n, p);
      if (j != kNoSpring) {
        l.partner[k] = j;
      } else {
        l.partner[k] = kSpringPartnerPending;
        waits = p;
      }
    }
    mine[k] = waits;
  }
  lists[i] = l;
}

struct IsId {
  __host__ __device__ bool operator()(uint32_t v) const { return v != kNoSpring; }
};

__global__ void find_owned_kernel(const uint32_t* __restrict__ asked, uint32_t m,
                                  const uint32_t* __restrict__ ids, const uint32_t* __restrict__ idx,
                                  uint32_t n, uint32_t owned, uint32_t* __restrict__ at,
                                  unsigned char* __restrict__ flags) {
  const uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= m) return;
  const uint32_t j = find_index(ids, idx, n, asked[k]);
  at[k] = j;
  flags[k] = j != kNoSpring && j < owned ? 1 : 0;
}

__global__ void resolve_waiting_kernel(SpringList* __restrict__ lists, uint32_t owned,
                                       const uint32_t* __restrict__ missing, const uint32_t* __restrict__ ids,
                                       const uint32_t* __restrict__ idx, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= owned) return;
  SpringList& l = lists[i];
  for (uint32_t k = 0; k < kSlots; ++k) {
    if (l.partner[k] != kSpringPartnerPending) continue;
    const uint32_t j = find_index(ids, idx, n, missing[static_cast<uint64_t>(i) * kSlots + k]);
    l.partner[k] = j;
    if (j == kNoSpring) l.rest[k] = 0.0f;  // (as remap_spring_list drops a removed partner's spring)
  }
}

__global__ void to_ids_kernel(SpringList* __restrict__ lists, const uint32_t* __restrict__ sorted_id,
                              const uint32_t* __restrict__ ghost, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || ghost[i]) return;  // (a ghost's list is its owner's, in ids all along)
  SpringList& l = lists[i];
  for (uint32_t k = 0; k < kSlots; ++k) {
    const uint32_t p = l.partner[k];
    if (p != kNoSpring) l.partner[k] = p < n ? sorted_id[p] : kNoSpring;
  }
}

__global__ void candidates_to_indices_kernel(uint32_t* __restrict__ candidates,
                                             const uint32_t* __restrict__ ghost, uint32_t n,
                                             const uint32_t* __restrict__ ids,
                                             const uint32_t* __restrict__ idx, uint32_t table_n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || !ghost[i]) return;
  uint32_t* theirs = candidates + static_cast<uint64_t>(i) * kSlots;
  for (uint32_t k = 0; k < kSlots; ++k) {
    const uint32_t c = theirs[k];
    if (c == kNoSpring) continue;
    const uint32_t j = find_index(ids, idx, table_n, c);
    theirs[k] = j == kNoSpring ? kSpringCandidateElsewhere : j;
  }
}

}  // namespace

DeviceHaloSprings::DeviceHaloSprings(uint32_t capacity, cudaStream_t stream) : capacity_(capacity) {
  const size_t n = std::max<uint32_t>(capacity, 1u);
  iota_.allocate(n, "halo spring table values");
  table_ids_.allocate(n, "halo spring table ids");
  table_idx_.allocate(n, "halo spring table indices");
  missing_.allocate(n * kSlots, "halo spring partners waiting");
  wanted_.allocate(n * kSlots, "halo spring partners wanted");
  words_.allocate(2, "halo spring counts");
  host_words_.allocate(2, "halo spring counts (host)");
  host_word_.allocate(1, "halo spring link word (host)");
  size_t sort = 0, select = 0;
  cuda_check(cub::DeviceRadixSort::SortPairs(
                 nullptr, sort, static_cast<const uint32_t*>(nullptr), static_cast<uint32_t*>(nullptr),
                 static_cast<const uint32_t*>(nullptr), static_cast<uint32_t*>(nullptr), static_cast<int>(n)),
             "halo spring table sort size query");
  cuda_check(cub::DeviceSelect::If(nullptr, select, static_cast<const uint32_t*>(nullptr),
                                   static_cast<uint32_t*>(nullptr), static_cast<uint64_t*>(nullptr),
                                   entries_of(n), IsId{}),
             "halo spring wanted size query");
  ensure_temp(std::max(sort, select));
  fill_iota(iota_.get(), static_cast<uint32_t>(n), stream);
  cuda_check(cudaStreamSynchronize(stream), "halo springs set-up");
}

void DeviceHaloSprings::ensure_temp(size_t bytes) {
  if (bytes <= temp_bytes_ && temp_.get()) return;
  temp_bytes_ = 0;
  temp_.allocate(std::max<size_t>(bytes, 1), "halo springs temporary storage");
  temp_bytes_ = std::max<size_t>(bytes, 1);
}

void DeviceHaloSprings::ensure_asked(uint32_t m) {
  if (m <= asked_flags_.size()) return;  // (allocated last: a failure half-way grows again)
  const size_t grown = static_cast<size_t>(m) + m / 2 + 64;
  asked_.allocate(grown, "halo spring ids asked");
  asked_idx_.allocate(grown, "halo spring ids asked: indices");
  found_.allocate(grown, "halo spring ids asked: found");
  asked_flags_.allocate(grown, "halo spring ids asked: flags");
  size_t select = 0;
  cuda_check(cub::DeviceSelect::Flagged(nullptr, select, asked_idx_.get(), asked_flags_.get(), found_.get(),
                                        words_.get(), static_cast<ItemCount>(grown)),
             "halo spring asked size query");
  ensure_temp(select);
}

void DeviceHaloSprings::index_ids(const uint32_t* ids, uint32_t n, cudaStream_t stream) {
  if (n > capacity_) throw Error(Status::Internal, "halo springs: more particles than the capacity");
  table_n_ = n;
  if (n == 0) return;
  size_t bytes = 0;
  cuda_check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, ids, table_ids_.get(), iota_.get(),
                                             table_idx_.get(), static_cast<int>(n), 0, 32, stream),
             "halo spring table sort size query");
  ensure_temp(bytes);
  cuda_check(cub::DeviceRadixSort::SortPairs(temp_.get(), bytes, ids, table_ids_.get(), iota_.get(),
                                             table_idx_.get(), static_cast<int>(n), 0, 32, stream),
             "halo spring table sort");
}

const uint32_t* DeviceHaloSprings::index_owned_lists(SpringList* lists, uint32_t owned, uint32_t* count,
                                                     cudaStream_t stream) {
  *count = 0;
  if (owned == 0) return host_ids_.get();
  if (owned > table_n_) throw Error(Status::Internal, "halo springs: owned particles outside the table");
  index_owned_kernel<<<blocks_for(owned, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      lists, owned, table_ids_.get(), table_idx_.get(), table_n_, missing_.get());
  check_launch("index_owned_kernel");
  // The waiting ids (usually none: one count comes back), then sorted and each kept once.
  const ItemCount entries = entries_of(owned);
  size_t bytes = 0;
  cuda_check(cub::DeviceSelect::If(nullptr, bytes, missing_.get(), wanted_.get(), words_.get(), entries,
                                   IsId{}, stream),
             "halo spring wanted size query");
  ensure_temp(bytes);
  cuda_check(cub::DeviceSelect::If(temp_.get(), bytes, missing_.get(), wanted_.get(), words_.get(), entries,
                                   IsId{}, stream),
             "halo spring wanted ids");
  cuda_check(
      cudaMemcpyAsync(host_words_.get(), words_.get(), sizeof(uint64_t), cudaMemcpyDeviceToHost, stream),
      "copy of the halo spring wanted count");
  cuda_check(cudaStreamSynchronize(stream), "halo spring wanted count");
  const uint64_t waiting = host_words_.get()[0];  // (up to 16 a particle: beyond 32 bits above 2^28)
  if (waiting == 0) return host_ids_.get();
  if (waiting > wanted_sorted_.size())
    wanted_sorted_.allocate(waiting + waiting / 2 + 64, "halo spring ids sorted");
  bytes = 0;
  cuda_check(cub::DeviceRadixSort::SortKeys(nullptr, bytes, wanted_.get(), wanted_sorted_.get(),
                                            static_cast<ItemCount>(waiting), 0, 32, stream),
             "halo spring wanted sort size query");
  size_t unique = 0;
  cuda_check(cub::DeviceSelect::Unique(nullptr, unique, wanted_sorted_.get(), wanted_.get(), words_.get() + 1,
                                       static_cast<ItemCount>(waiting), stream),
             "halo spring wanted unique size query");
  ensure_temp(std::max(bytes, unique));
  cuda_check(cub::DeviceRadixSort::SortKeys(temp_.get(), bytes, wanted_.get(), wanted_sorted_.get(),
                                            static_cast<ItemCount>(waiting), 0, 32, stream),
             "halo spring wanted sort");
  cuda_check(cub::DeviceSelect::Unique(temp_.get(), unique, wanted_sorted_.get(), wanted_.get(),
                                       words_.get() + 1, static_cast<ItemCount>(waiting), stream),
             "halo spring wanted unique");
  if (waiting > host_ids_count_) {
    host_ids_count_ = 0;
    host_ids_.allocate(waiting, "halo spring wanted ids (host)");
    host_ids_count_ = waiting;
  }
  // (At most `waiting` unique ids: the whole range comes down with the count, one wait.)
  cuda_check(cudaMemcpyAsync(host_words_.get() + 1, words_.get() + 1, sizeof(uint64_t),
                             cudaMemcpyDeviceToHost, stream),
             "copy of the halo spring unique count");
  cuda_check(cudaMemcpyAsync(host_ids_.get(), wanted_.get(), sizeof(uint32_t) * waiting,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the halo spring wanted ids");
  cuda_check(cudaStreamSynchronize(stream), "halo spring wanted ids");
  *count = static_cast<uint32_t>(host_words_.get()[1]);  // (distinct uint32 ids: fits)
  return host_ids_.get();
}

const uint32_t* DeviceHaloSprings::find_owned(const uint32_t* asked, uint32_t m, uint32_t owned,
                                              uint32_t* found, cudaStream_t stream) {
  *found = 0;
  if (m == 0 || table_n_ == 0) return found_.get();
  ensure_asked(m);
  cuda_check(cudaMemcpyAsync(asked_.get(), asked, sizeof(uint32_t) * m, cudaMemcpyHostToDevice, stream),
             "copy of the spring ids asked");
  find_owned_kernel<<<blocks_for(m, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      asked_.get(), m, table_ids_.get(), table_idx_.get(), table_n_, owned, asked_idx_.get(),
      asked_flags_.get());
  check_launch("find_owned_kernel");
  size_t bytes = 0;
  cuda_check(cub::DeviceSelect::Flagged(nullptr, bytes, asked_idx_.get(), asked_flags_.get(), found_.get(),
                                        words_.get(), static_cast<ItemCount>(m), stream),
             "halo spring asked size query");
  ensure_temp(bytes);
  cuda_check(cub::DeviceSelect::Flagged(temp_.get(), bytes, asked_idx_.get(), asked_flags_.get(),
                                        found_.get(), words_.get(), static_cast<ItemCount>(m), stream),
             "halo spring ids found");
  cuda_check(
      cudaMemcpyAsync(host_words_.get(), words_.get(), sizeof(uint64_t), cudaMemcpyDeviceToHost, stream),
      "copy of the halo spring found count");
  cuda_check(cudaStreamSynchronize(stream), "halo spring ids found");  // (asked: pageable, copied by now)
  *found = static_cast<uint32_t>(host_words_.get()[0]);                // (at most m)
  return found_.get();
}

void DeviceHaloSprings::resolve_waiting(SpringList* lists, uint32_t owned, cudaStream_t stream) {
  if (owned == 0) return;
  resolve_waiting_kernel<<<blocks_for(owned, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      lists, owned, missing_.get(), table_ids_.get(), table_idx_.get(), table_n_);
  check_launch("resolve_waiting_kernel");
}

void DeviceHaloSprings::enqueue_to_ids(SpringList* lists, const uint32_t* sorted_id, const uint32_t* ghost,
                                       uint32_t n, cudaStream_t stream) const {
  if (n == 0) return;
  to_ids_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(lists, sorted_id, ghost,
                                                                                    n);
  check_launch("to_ids_kernel");
}

void DeviceHaloSprings::candidates_to_indices(uint32_t* candidates, const uint32_t* ghost, uint32_t n,
                                              cudaStream_t stream) const {
  if (n == 0) return;
  candidates_to_indices_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      candidates, ghost, n, table_ids_.get(), table_idx_.get(), table_n_);
  check_launch("candidates_to_indices_kernel");
}

uint64_t DeviceHaloSprings::bytes() const {
  return iota_.bytes() + table_ids_.bytes() + table_idx_.bytes() + missing_.bytes() + wanted_.bytes() +
         wanted_sorted_.bytes() + asked_.bytes() + asked_idx_.bytes() + found_.bytes() +
         asked_flags_.bytes() + words_.bytes() + temp_.bytes();
}

}  // namespace sph
