// SPDX-License-Identifier: MIT
#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <string>

#include "../src/core/exact_float_sum.h"
#include "../src/physics/grid_hash.h"
#include "device_halo.h"
#include "device_iota.h"
#include "dfsph_solver.h"
#include "kernel_launch.h"

namespace sph {
namespace {

// dst[k] = src[idx[k]] for k < m, `words` 32-bit words a particle.
__global__ void gather_words_kernel(const uint32_t* __restrict__ src, uint32_t words,
                                    const uint32_t* __restrict__ idx, uint32_t m,
                                    uint32_t* __restrict__ dst) {
  const uint64_t t = static_cast<uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (t >= static_cast<uint64_t>(m) * words) return;
  const uint64_t k = t / words, w = t % words;
  dst[t] = src[static_cast<uint64_t>(idx[k]) * words + w];
}

// What each record takes from a particle and gives back to its ghost (core/halo_records.h).
template <class Record>
struct HaloRecordFields;

template <>
struct HaloRecordFields<HaloDensityRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's density records";
  static constexpr const char* kCopyIn = "copy of the ghosts' density records";
  __device__ static HaloDensityRecord pack(const ParticleArrays& a, uint32_t i) {
    return HaloDensityRecord{a.sorted_id[i], a.density[i], a.sorted_position[i].w, a.sorted_velocity[i].w,
                             a.neighbor_count ? a.neighbor_count[i] : 0u};
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloDensityRecord& r) {
    a.density[i] = r.density;
    a.sorted_position[i].w = r.pressure;
    a.sorted_velocity[i].w = r.inv_density;
    if (a.neighbor_count) a.neighbor_count[i] = r.neighbors;
  }
};

template <>
struct HaloRecordFields<HaloNormalRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's colour normals";
  static constexpr const char* kCopyIn = "copy of the ghosts' colour normals";
  __device__ static HaloNormalRecord pack(const ParticleArrays& a, uint32_t i) {
    return HaloNormalRecord{a.sorted_id[i], {0u, 0u, 0u}, a.colour_normal[i]};
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloNormalRecord& r) {
    a.colour_normal[i] = r.normal;
  }
};

// DFSPH (core/dfsph_jacobi_loop.h says when each crosses): after its density pass, the density,
// factor, 1 / density and neighbour count; in a solve, the velocities of the solve (the arrays'
// sorted_velocity: the caller points it at the density solve's v*) and the pressure steps k.
template <>
struct HaloRecordFields<HaloDfsphDensityRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's DFSPH density records";
  static constexpr const char* kCopyIn = "copy of the ghosts' DFSPH density records";
  __device__ static HaloDfsphDensityRecord pack(const ParticleArrays& a, uint32_t i) {
    return HaloDfsphDensityRecord{a.sorted_id[i], a.density[i], a.dfsph_factor[i], a.sorted_velocity[i].w,
                                  a.neighbor_count[i]};
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloDfsphDensityRecord& r) {
    a.density[i] = r.density;
    a.dfsph_factor[i] = r.factor;
    a.sorted_velocity[i].w = r.inv_density;
    a.neighbor_count[i] = r.neighbors;
  }
};

template <>
struct HaloRecordFields<HaloVelocityRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's DFSPH velocities";
  static constexpr const char* kCopyIn = "copy of the ghosts' DFSPH velocities";
  __device__ static HaloVelocityRecord pack(const ParticleArrays& a, uint32_t i) {
    return HaloVelocityRecord{a.sorted_id[i], {0u, 0u, 0u}, a.sorted_velocity[i]};
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloVelocityRecord& r) {
    a.sorted_velocity[i] = r.velocity;
  }
};

template <>
struct HaloRecordFields<HaloDfsphStepRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's DFSPH pressure steps";
  static constexpr const char* kCopyIn = "copy of the ghosts' DFSPH pressure steps";
  __device__ static HaloDfsphStepRecord pack(const ParticleArrays& a, uint32_t i) {
    return HaloDfsphStepRecord{a.sorted_id[i], a.dfsph_step[i]};
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloDfsphStepRecord& r) {
    a.dfsph_step[i] = r.k;
  }
};

// Springs' linking (cuda_halo_springs.cu): an owned particle's candidates as ids; a ghost takes
// them as ids, which DeviceHaloSprings::candidates_to_indices then finds among the particles here.
template <>
struct HaloRecordFields<HaloSpringCandidateRecord> {
  static constexpr const char* kCopyOut = "copy of the halo's spring candidates";
  static constexpr const char* kCopyIn = "copy of the ghosts' spring candidates";
  __device__ static HaloSpringCandidateRecord pack(const ParticleArrays& a, uint32_t i) {
    HaloSpringCandidateRecord r;
    r.id = a.sorted_id[i];
    const uint32_t* mine = a.spring_candidates + static_cast<uint64_t>(i) * kSpringSlots;
    for (uint32_t k = 0; k < kSpringSlots; ++k)
      r.candidate[k] = mine[k] == kNoSpring ? kNoSpring : a.sorted_id[mine[k]];
    return r;
  }
  __device__ static void apply(const ParticleArrays& a, uint32_t i, const HaloSpringCandidateRecord& r) {
    uint32_t* theirs = a.spring_candidates + static_cast<uint64_t>(i) * kSpringSlots;
    for (uint32_t k = 0; k < kSpringSlots; ++k) theirs[k] = r.candidate[k];
  }
};

template <class Record>
__global__ void pack_records_kernel(ParticleArrays a, const uint32_t* __restrict__ idx, uint32_t m,
                                    Record* __restrict__ out) {
  const uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= m) return;
  out[k] = HaloRecordFields<Record>::pack(a, idx[k]);
}

template <class Record>
__global__ void apply_records_kernel(ParticleArrays a, const uint32_t* __restrict__ idx, uint32_t m,
                                     const Record* __restrict__ in, uint32_t* mismatch) {
  const uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= m) return;
  const uint32_t i = idx[k];
  const Record r = in[k];
  if (r.id != a.sorted_id[i]) {
    atomicExch(mismatch, 1u);
    return;
  }
  HaloRecordFields<Record>::apply(a, i, r);
}

}  // namespace

DeviceHalo::DeviceHalo(uint32_t capacity, int ranks, cudaStream_t stream)
    : capacity_(capacity), ranks_(ranks) {
  // The lists hold two entries a particle and CUB counts items in int: 2 x capacity must stay
  // below 2^31 (a rank at the world's limit of 2^30 would overflow it).
  if (capacity > kMaxHaloCapacity)
    throw Error(Status::Capacity, "a distributed CUDA rank holds at most " +
                                      std::to_string(kMaxHaloCapacity) +
                                      " particles (its halo lists count two entries a particle in 32 bits); "
                                      "asked for " +
                                      std::to_string(capacity));
  const size_t n = std::max<uint32_t>(capacity, 1u);
  key_bits_ = 1;
  while ((1ull << key_bits_) <= 2ull * static_cast<uint64_t>(ranks)) ++key_bits_;
  cuts_.allocate(static_cast<size_t>(std::max(ranks - 1, 1)), "halo slab cuts");
  layers_.allocate(n, "halo layers");
  origin_.allocate(n, "halo ghosts' ranks");
  // Two entries a particle: at most two other slabs meet a particle's layer and those beside it
  // (core/slab_rules.h), and it is listed for each.
  keys_in_.allocate(2 * n, "halo list keys");
  keys_out_.allocate(2 * n, "halo sorted list keys");
  values_.allocate(2 * n, "halo list values");
  list_.allocate(2 * n, "halo index lists");
  keep_.allocate(n, "halo kept list");
  kept_flags_.allocate(n, "halo kept flags");
  const size_t words = 2 * static_cast<size_t>(ranks) + 3;
  words_.allocate(words, "halo list starts");
  iota_.allocate(n, "halo sort values");
  visit_.allocate(n, "halo visit order");
  sorted_keys_.allocate(n, "halo sorted keys");
  mismatch_.allocate(1, "halo id check");
  error_bins_.allocate(kDfsphRankCgWords, "halo DFSPH error bins");
  host_error_bins_.allocate(kDfsphRankCgWords, "halo DFSPH error bins (host)");
  host_cuts_.allocate(static_cast<size_t>(std::max(ranks - 1, 1)), "halo slab cuts (host)");
  host_words_.allocate(words, "halo list starts (host)");
  std::fill(host_words_.get(), host_words_.get() + words, 0u);
  cuda_check(
      cub::DeviceRadixSort::SortPairs(nullptr, sort_temp_bytes_, static_cast<const uint64_t*>(nullptr),
                                      static_cast<uint64_t*>(nullptr), static_cast<const uint32_t*>(nullptr),
                                      static_cast<uint32_t*>(nullptr), static_cast<int>(n)),
      "halo key sort size query");
  sort_temp_.allocate(std::max<size_t>(sort_temp_bytes_, 1), "halo key sort temporary storage");
  lists_temp_bytes_ = lists_temp_bytes(static_cast<uint32_t>(2 * n));
  lists_temp_.allocate(std::max<size_t>(lists_temp_bytes_, 1), "halo lists temporary storage");
  // On the world's stream: the legacy default stream or a device-wide synchronisation would also
  // wait for an engine's streams and for other worlds' frames.
  fill_iota(iota_.get(), static_cast<uint32_t>(n), stream);
  cuda_check(cudaMemsetAsync(mismatch_.get(), 0, sizeof(uint32_t), stream), "halo id check reset");
  cuda_check(cudaStreamSynchronize(stream), "halo set-up");
}

void DeviceHalo::ensure_device(size_t bytes) {
  if (staging_.bytes() >= bytes) return;
  staging_.allocate(bytes + bytes / 2 + 256, "halo staging");
}

void DeviceHalo::ensure_host(size_t bytes) {
  if (host_staging_bytes_ >= bytes) return;
  const size_t grown = bytes + bytes / 2 + 256;
  host_staging_bytes_ = 0;  // allocate() frees the old buffer first: a failure leaves none
  host_staging_.allocate(grown, "halo staging (host)");
  host_staging_bytes_ = grown;
}

const unsigned char* DeviceHalo::pack(const HaloArray* arrays, int count, const uint32_t* idx, uint32_t m,
                                      cudaStream_t stream) {
  size_t record = 0;
  for (int k = 0; k < count; ++k) record += arrays[k].bytes;
  ensure_device(record * m);
  ensure_host(record * m);
  size_t offset = 0;
  for (int k = 0; k < count && m > 0; ++k) {
    const uint32_t words = arrays[k].bytes / 4u;
    const uint64_t items = static_cast<uint64_t>(m) * words;
    gather_words_kernel<<<static_cast<unsigned>((items + kDefaultBlockSize - 1) / kDefaultBlockSize),
                          kDefaultBlockSize, 0, stream>>>(
        reinterpret_cast<const uint32_t*>(arrays[k].data), words, idx, m,
        reinterpret_cast<uint32_t*>(staging_.get() + offset));
    check_launch("gather_words_kernel");
    offset += static_cast<size_t>(arrays[k].bytes) * m;
  }
  if (offset > 0)
    cuda_check(cudaMemcpyAsync(host_staging_.get(), staging_.get(), offset, cudaMemcpyDeviceToHost, stream),
               "copy of the halo's leaving particles");
  cuda_check(cudaStreamSynchronize(stream), "halo pack");
  return host_staging_.get();
}

void DeviceHalo::keep(const HaloArray* arrays, int count, const uint32_t* idx, uint32_t m,
                      cudaStream_t stream) {
  uint32_t widest = 0;
  for (int k = 0; k < count; ++k) widest = std::max(widest, arrays[k].bytes);
  ensure_device(static_cast<size_t>(widest) * m);
  for (int k = 0; k < count && m > 0; ++k) {
    const uint32_t words = arrays[k].bytes / 4u;
    const uint64_t items = static_cast<uint64_t>(m) * words;
    gather_words_kernel<<<static_cast<unsigned>((items + kDefaultBlockSize - 1) / kDefaultBlockSize),
                          kDefaultBlockSize, 0, stream>>>(reinterpret_cast<const uint32_t*>(arrays[k].data),
                                                          words, idx, m,
                                                          reinterpret_cast<uint32_t*>(staging_.get()));
    check_launch("gather_words_kernel");
    cuda_check(cudaMemcpyAsync(arrays[k].data, staging_.get(), static_cast<size_t>(arrays[k].bytes) * m,
                               cudaMemcpyDeviceToDevice, stream),
               "halo compaction");
  }
}

void DeviceHalo::unpack(const HaloArray* arrays, int count, const unsigned char* bytes, uint32_t m,
                        uint32_t first, cudaStream_t stream) {
  if (m == 0) return;
  if (static_cast<uint64_t>(first) + m > capacity_)
    throw Error(Status::Internal, "halo: arriving particles past the capacity");
  size_t record = 0;
  for (int k = 0; k < count; ++k) record += arrays[k].bytes;
  ensure_host(record * m);
  std::copy(bytes, bytes + record * m, host_staging_.get());
  size_t offset = 0;
  for (int k = 0; k < count; ++k) {
    const size_t b = arrays[k].bytes;
    cuda_check(cudaMemcpyAsync(arrays[k].data + b * first, host_staging_.get() + offset, b * m,
                               cudaMemcpyHostToDevice, stream),
               "copy of the halo's arriving particles");
    offset += b * m;
  }
  cuda_check(cudaStreamSynchronize(stream), "halo unpack");  // (the pinned staging is reused)
}

void DeviceHalo::enqueue_visit(const uint64_t* keys, uint32_t n, cudaStream_t stream) {
  if (n > capacity_) throw Error(Status::Internal, "halo: more particles than the capacity");
  if (n == 0) return;
  size_t bytes = sort_temp_bytes_;
  cuda_check(cub::DeviceRadixSort::SortPairs(sort_temp_.get(), bytes, keys, sorted_keys_.get(), iota_.get(),
                                             visit_.get(), static_cast<int>(n), 0, 64, stream),
             "halo key sort");
}

template <class Record>
const Record* DeviceHalo::pack_records(const ParticleArrays& a, const uint32_t* idx, uint32_t m,
                                       cudaStream_t stream) {
  const size_t bytes = sizeof(Record) * m;
  ensure_device(bytes);
  ensure_host(bytes);
  if (m > 0) {
    pack_records_kernel<Record><<<blocks_for(m, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
        a, idx, m, reinterpret_cast<Record*>(staging_.get()));
    check_launch("pack_records_kernel");
    cuda_check(cudaMemcpyAsync(host_staging_.get(), staging_.get(), bytes, cudaMemcpyDeviceToHost, stream),
               HaloRecordFields<Record>::kCopyOut);
  }
  cuda_check(cudaStreamSynchronize(stream), HaloRecordFields<Record>::kCopyOut);
  return reinterpret_cast<const Record*>(host_staging_.get());
}

template <class Record>
void DeviceHalo::enqueue_apply_records(const ParticleArrays& a, const uint32_t* idx, const Record* records,
                                       uint32_t m, cudaStream_t stream) {
  if (m == 0) return;
  const size_t bytes = sizeof(Record) * m;
  ensure_device(bytes);
  ensure_host(bytes);
  std::copy(records, records + m, reinterpret_cast<Record*>(host_staging_.get()));
  cuda_check(cudaMemcpyAsync(staging_.get(), host_staging_.get(), bytes, cudaMemcpyHostToDevice, stream),
             HaloRecordFields<Record>::kCopyIn);
  apply_records_kernel<Record><<<blocks_for(m, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      a, idx, m, reinterpret_cast<const Record*>(staging_.get()), mismatch_.get());
  check_launch("apply_records_kernel");
  // (The pinned staging is not touched again before the stream's next wait.)
}

// Each record's pack and apply (HaloRecordFields above).
#define SPH_HALO_RECORD(Record)                                                                             \
  template const Record* DeviceHalo::pack_records<Record>(const ParticleArrays&, const uint32_t*, uint32_t, \
                                                          cudaStream_t);                                    \
  template void DeviceHalo::enqueue_apply_records<Record>(const ParticleArrays&, const uint32_t*,           \
                                                          const Record*, uint32_t, cudaStream_t);
SPH_HALO_RECORD(HaloDensityRecord)
SPH_HALO_RECORD(HaloNormalRecord)
SPH_HALO_RECORD(HaloDfsphDensityRecord)
SPH_HALO_RECORD(HaloVelocityRecord)
SPH_HALO_RECORD(HaloDfsphStepRecord)
SPH_HALO_RECORD(HaloSpringCandidateRecord)
#undef SPH_HALO_RECORD

const int64_t* DeviceHalo::download_error_bins(cudaStream_t stream, uint32_t words) {
  if (words > kDfsphRankCgWords) throw Error(Status::Internal, "halo: more DFSPH error words than allocated");
  cuda_check(cudaMemcpyAsync(host_error_bins_.get(), error_bins_.get(), sizeof(int64_t) * words,
                             cudaMemcpyDeviceToHost, stream),
             "copy of the DFSPH error bins");
  cuda_check(cudaStreamSynchronize(stream), "the DFSPH error bins");
  return host_error_bins_.get();
}

uint64_t DeviceHalo::bytes() const {
  return cuts_.bytes() + layers_.bytes() + origin_.bytes() + keys_in_.bytes() + keys_out_.bytes() +
         values_.bytes() + list_.bytes() + keep_.bytes() + kept_flags_.bytes() + words_.bytes() +
         lists_temp_.bytes() + iota_.bytes() + visit_.bytes() + sorted_keys_.bytes() + sort_temp_.bytes() +
         mismatch_.bytes() + error_bins_.bytes() + staging_.bytes();
}

}  // namespace sph
