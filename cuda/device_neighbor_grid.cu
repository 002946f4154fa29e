// SPDX-License-Identifier: MIT
#include <algorithm>

#include <cub/device/device_radix_sort.cuh>

#include "../src/physics/grid_fit.h"
#include "../src/physics/grid_hash.h"
#include "block_reduce.cuh"
#include "device_lower_bound.cuh"
#include "device_neighbor_grid.h"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr unsigned kExtentBlocks = 1024;  // grid-stride: few blocks, so few atomics a sort

__device__ __forceinline__ uint32_t cell_code(int32_t c) {
  return static_cast<uint32_t>(static_cast<int64_t>(c) + 2147483648ll);
}

// The particles' cell extent into live->lowest_code / highest_code (zero on entry: zeroed at the
// grid's creation and again by fit_shape_kernel after each read): maxima only, so any order of the
// blocks gives the same record.
__global__ void __launch_bounds__(kDefaultBlockSize)
    extent_kernel(float inv_cell_size, const Float4* __restrict__ positions, uint32_t n, LiveGridShape* live,
                  FrameState* state) {
  mark_stage(state, kStageHashSort);
  __shared__ uint32_t warp_codes[kDefaultBlockSize / 32][6];
  uint32_t codes[6] = {0, 0, 0, 0, 0, 0};
  for (uint32_t i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const Float4 p = positions[i];
    const uint32_t c[3] = {cell_code(cell_coordinate(p.x, inv_cell_size)),
                           cell_code(cell_coordinate(p.y, inv_cell_size)),
                           cell_code(cell_coordinate(p.z, inv_cell_size))};
    for (int a = 0; a < 3; ++a) {
      codes[a] = max(codes[a], ~c[a]);
      codes[3 + a] = max(codes[3 + a], c[a]);
    }
  }
  const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
  for (int k = 0; k < 6; ++k) {
    const uint32_t v = warp_reduce(codes[k], MaxOp{});
    if (lane == 0) warp_codes[warp][k] = v;
  }
  __syncthreads();
  if (threadIdx.x < 6) {
    uint32_t v = 0;
    for (unsigned w = 0; w < (blockDim.x + 31u) / 32u; ++w) v = max(v, warp_codes[w][threadIdx.x]);
    if (v != 0)
      atomicMax(threadIdx.x < 3 ? &live->lowest_code[threadIdx.x] : &live->highest_code[threadIdx.x - 3], v);
  }
}

// One thread: the dims for the extent within the table's slots (no particle: the table's own),
// then the extent zeroed for the next sort's extent_kernel (one graph node a substep less than a
// memset before it).
__global__ void fit_shape_kernel(GridShape table, LiveGridShape* live) {
  uint32_t lowest[3], highest[3];
  for (int a = 0; a < 3; ++a) {
    lowest[a] = live->lowest_code[a];
    highest[a] = live->highest_code[a];
    live->lowest_code[a] = 0;
    live->highest_code[a] = 0;
  }
  if (highest[0] == 0) {
    live->shape = table;
    return;
  }
  CellCoord lo, hi;
  lo.x = static_cast<int32_t>(static_cast<int64_t>(~lowest[0]) - 2147483648ll);
  lo.y = static_cast<int32_t>(static_cast<int64_t>(~lowest[1]) - 2147483648ll);
  lo.z = static_cast<int32_t>(static_cast<int64_t>(~lowest[2]) - 2147483648ll);
  hi.x = static_cast<int32_t>(static_cast<int64_t>(highest[0]) - 2147483648ll);
  hi.y = static_cast<int32_t>(static_cast<int64_t>(highest[1]) - 2147483648ll);
  hi.z = static_cast<int32_t>(static_cast<int64_t>(highest[2]) - 2147483648ll);
  live->shape = fit_grid_shape(table.inv_cell_size, lo, hi, static_cast<double>(table.cell_count));
}

__global__ void hash_kernel(GridShape table, const LiveGridShape* __restrict__ live,
                            const Float4* __restrict__ positions, uint32_t n,
                            const uint32_t* __restrict__ visit, uint32_t* __restrict__ keys,
                            uint32_t* __restrict__ values, FrameState* state) {
  mark_stage(state, kStageHashSort);
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const GridShape shape = live ? live->shape : table;
  const uint32_t k = visit ? visit[i] : i;
  keys[i] = cell_hash_of_position(shape, xyz(positions[k]));
  values[i] = k;
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
    bounds[threadIdx.x] =
        cell > cell_count ? n : lower_bound_u32(sorted_keys, 0, n, static_cast<uint32_t>(cell));
  }
  __syncthreads();
  const uint32_t c = first_cell + threadIdx.x;
  const uint32_t start = c > cell_count ? n : lower_bound_u32(sorted_keys, bounds[0], bounds[1], c);
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
                                       SortScratch scratch, void* spare, size_t spare_bytes,
                                       cudaStream_t stream, bool fit_to_extent)
    : shape_(shape),
      fit_to_extent_(fit_to_extent),
      capacity_(capacity),
      max_per_cell_(max_per_cell),
      key_bits_(bits_for(shape.cell_count - 1)),
      scratch_(scratch) {
  cell_start_.allocate(static_cast<size_t>(shape.cell_count) + 1, "cell-start table");
  if (fit_to_extent_) {
    live_.allocate(1, "the grid's fitted shape");
    // On the world's stream, which every reader of the shape uses: the legacy default stream
    // would also wait for (and hold up) an engine's blocking streams.
    cuda_check(cudaMemsetAsync(live_.get(), 0, sizeof(LiveGridShape), stream), "the grid's extent reset");
    cuda_check(cudaStreamSynchronize(stream), "the grid's extent reset");
  }
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
  if (fit_to_extent_) {
    // The extent of the particles the hash takes (visit is a permutation of [0, n)).
    const unsigned blocks = std::min(blocks_for(n, kDefaultBlockSize), kExtentBlocks);
    extent_kernel<<<blocks, kDefaultBlockSize, 0, stream>>>(shape_.inv_cell_size, positions, n, live_.get(),
                                                            state);
    check_launch("extent_kernel");
    fit_shape_kernel<<<1, 1, 0, stream>>>(shape_, live_.get());
    check_launch("fit_shape_kernel");
  }
  hash_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(
      shape_, fit_to_extent_ ? live_.get() : nullptr, positions, n, visit, scratch_.keys[0],
      scratch_.values[0], state);
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
