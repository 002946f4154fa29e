// SPDX-License-Identifier: MIT
#include <cub/device/device_radix_sort.cuh>

#include "../src/physics/grid_hash.h"
#include "device_neighbor_grid.h"
#include "kernel_launch.h"

namespace sph {
namespace {

__global__ void hash_kernel(GridShape shape, const Float4* __restrict__ positions, uint32_t n,
                            const uint32_t* __restrict__ visit, uint32_t* __restrict__ keys,
                            uint32_t* __restrict__ values, FrameState* state) {
  mark_stage(state, kStageHashSort);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const uint32_t k = visit ? visit[i] : i;
  keys[i] = cell_hash_of_position(shape, xyz(positions[k]));
  values[i] = k;
}

// First index in [lo, hi) whose key is >= cell, or hi.
__device__ uint32_t lower_bound(const uint32_t* __restrict__ keys, uint32_t lo, uint32_t hi, uint32_t cell) {
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo) / 2;
    if (keys[mid] < cell)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// One thread per table entry c in [0, cell_count]: cell_start[c] = first sorted index whose
// key is >= c. Each block first bounds its cells' answers by two searches over all keys, so
// the per-thread search runs over the few particles of the block's cells. The block's starts
// then give each cell's crowd, checked against the cap (src/core/crowded_cell.h).
__global__ void __launch_bounds__(kDefaultBlockSize)
    cell_start_kernel(const uint32_t* __restrict__ sorted_keys, uint32_t n, uint32_t cell_count,
                      uint32_t max_per_cell, uint32_t* __restrict__ cell_start, FrameState* state) {
  mark_stage(state, kStageCellRanges);
  __shared__ uint32_t bounds[2];
  __shared__ uint32_t starts[kDefaultBlockSize + 1];
  const uint32_t first_cell = blockIdx.x * blockDim.x;
  if (threadIdx.x < 2) {
    const uint64_t cell = static_cast<uint64_t>(first_cell) + (threadIdx.x == 0 ? 0u : blockDim.x);
    bounds[threadIdx.x] = cell > cell_count ? n : lower_bound(sorted_keys, 0, n, static_cast<uint32_t>(cell));
  }
  __syncthreads();
  const uint32_t c = first_cell + threadIdx.x;
  const uint32_t start = c > cell_count ? n : lower_bound(sorted_keys, bounds[0], bounds[1], c);
  starts[threadIdx.x] = start;
  if (threadIdx.x == 0) starts[blockDim.x] = bounds[1];
  __syncthreads();
  if (c > cell_count) return;
  cell_start[c] = start;
  const uint32_t held = starts[threadIdx.x + 1] - start;
  if (c < cell_count && held > max_per_cell)
    atomicMax(&state->crowded_key, static_cast<unsigned long long>(held) << 32 | c);
}

int bits_for(uint32_t max_value) {
  int bits = 1;
  while (bits < 32 && (max_value >> bits) != 0) ++bits;
  return bits;
}

}  // namespace

DeviceNeighborGrid::DeviceNeighborGrid(const GridShape& shape, uint32_t capacity, uint32_t max_per_cell,
                                       SortScratch scratch, void* spare, size_t spare_bytes)
    : shape_(shape),
      capacity_(capacity),
      max_per_cell_(max_per_cell),
      key_bits_(bits_for(shape.cell_count - 1)),
      scratch_(scratch) {
  cell_start_.allocate(static_cast<size_t>(shape.cell_count) + 1, "cell-start table");
  cub::DoubleBuffer<uint32_t> keys(scratch_.keys[0], scratch_.keys[1]);
  cub::DoubleBuffer<uint32_t> values(scratch_.values[0], scratch_.values[1]);
  cuda_check(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes_, keys, values, static_cast<int>(capacity),
                                             0, key_bits_),
             "radix sort size query");
  if (temp_bytes_ <= spare_bytes) {
    temp_storage_ = spare;
  } else {
    temp_.allocate(temp_bytes_, "radix sort temporary storage");
    temp_storage_ = temp_.get();
  }
}

void DeviceNeighborGrid::enqueue_sort(const Float4* positions, uint32_t n, FrameState* state,
                                      cudaStream_t stream, const uint32_t* visit) {
  hash_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      shape_, positions, n, visit, scratch_.keys[0], scratch_.values[0], state);
  check_launch("hash_kernel");
  cub::DoubleBuffer<uint32_t> keys(scratch_.keys[0], scratch_.keys[1]);
  cub::DoubleBuffer<uint32_t> values(scratch_.values[0], scratch_.values[1]);
  size_t needed = 0;
  cuda_check(
      cub::DeviceRadixSort::SortPairs(nullptr, needed, keys, values, static_cast<int>(n), 0, key_bits_),
      "radix sort size query");
  if (needed > temp_bytes_)
    throw Error(Status::Internal, "radix sort: needs " + std::to_string(needed) +
                                      " bytes of temporary storage for " + std::to_string(n) +
                                      " particles, more than the " + std::to_string(temp_bytes_) +
                                      " reserved for the capacity");
  size_t bytes = temp_bytes_;
  cuda_check(cub::DeviceRadixSort::SortPairs(temp_storage_, bytes, keys, values, static_cast<int>(n), 0,
                                             key_bits_, stream),
             "radix sort");
  sorted_keys_ = keys.Current();
  order_ = values.Current();
}

void DeviceNeighborGrid::enqueue_cell_starts(uint32_t n, FrameState* state, cudaStream_t stream) {
  const uint32_t entries = shape_.cell_count + 1;
  cell_start_kernel<<<blocks_for(entries, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      sorted_keys_, n, shape_.cell_count, max_per_cell_, cell_start_.get(), state);
  check_launch("cell_start_kernel");
}

}  // namespace sph
