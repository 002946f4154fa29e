// SPDX-License-Identifier: MIT
// Block-wide reductions used by several kernels. Every one gives the same bits whatever the
// order in which blocks run: maxima are exact, and sums are combined in a fixed tree.
#pragma once

#include <stdint.h>

namespace sph {

// Max of non-negative floats over the block, then one atomicMax per block on the float bits
// (for non-negative floats the unsigned order is the float order). Call from every thread.
__device__ __forceinline__ void block_max_to(uint32_t* target, float value) {
  __shared__ float warp_max[32];
  for (int offset = 16; offset > 0; offset >>= 1)
    value = fmaxf(value, __shfl_xor_sync(0xffffffffu, value, offset));
  const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
  if (lane == 0) warp_max[warp] = value;
  __syncthreads();
  if (warp == 0) {
    const unsigned warps = (blockDim.x + 31u) >> 5;
    value = lane < warps ? warp_max[lane] : 0.0f;
    for (int offset = 16; offset > 0; offset >>= 1)
      value = fmaxf(value, __shfl_xor_sync(0xffffffffu, value, offset));
    if (lane == 0 && value > 0.0f) atomicMax(target, __float_as_uint(value));
  }
}

}  // namespace sph
