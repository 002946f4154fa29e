// SPDX-License-Identifier: MIT
// The first index in [lo, hi) of an ascending key array whose key is >= value, or hi: the cell
// table's starts (device_neighbor_grid.cu) and the halo lists' starts (device_halo_lists.cu).
#pragma once

#include <stdint.h>

namespace sph {

__device__ __forceinline__ uint32_t lower_bound_u32(const uint32_t* __restrict__ keys, uint32_t lo,
                                                    uint32_t hi, uint32_t value) {
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo) / 2;
    if (keys[mid] < value)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

}  // namespace sph
