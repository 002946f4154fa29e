// SPDX-License-Identifier: MIT
// Block-wide reductions used by several kernels. Every one gives the same bits whatever the
// order in which blocks run: maxima and minima are exact, and sums are combined in a fixed tree.
#pragma once

#include <stdint.h>

namespace sph {

struct MaxOp {
  __device__ __forceinline__ float operator()(float a, float b) const { return fmaxf(a, b); }
  __device__ __forceinline__ uint32_t operator()(uint32_t a, uint32_t b) const { return max(a, b); }
};
struct MinOp {
  __device__ __forceinline__ float operator()(float a, float b) const { return fminf(a, b); }
};

// The reduction of `value` over a full warp, in every lane (a butterfly: all lanes end equal).
template <typename T, typename Op>
__device__ __forceinline__ T warp_reduce(T value, Op op) {
  for (int offset = 16; offset > 0; offset >>= 1)
    value = op(value, __shfl_xor_sync(0xffffffffu, value, offset));
  return value;
}

// The reduction of `value` over the block, valid in warp 0 (every lane of it); the other warps
// get their own warp's partial. Call from every thread of the block. `scratch` is 32 elements
// of shared memory that no other thread touches until the block's next __syncthreads after this
// returns; `identity` fills the lanes past the last warp (for fminf/fmaxf, NaN values drop out).
template <typename T, typename Op>
__device__ __forceinline__ T block_reduce(T value, T identity, Op op, T* scratch) {
  value = warp_reduce(value, op);
  const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
  if (lane == 0) scratch[warp] = value;
  __syncthreads();
  if (warp == 0) {
    const unsigned warps = (blockDim.x + 31u) >> 5;
    value = warp_reduce(lane < warps ? scratch[lane] : identity, op);
  }
  return value;
}

// Max of non-negative floats over the block, then one atomicMax per block on the float bits
// (for non-negative floats the unsigned order is the float order). Call from every thread.
__device__ __forceinline__ void block_max_to(uint32_t* target, float value) {
  __shared__ float warp_max[32];
  value = block_reduce(value, 0.0f, MaxOp{}, warp_max);
  if (threadIdx.x == 0 && value > 0.0f) atomicMax(target, __float_as_uint(value));
}

}  // namespace sph
