// SPDX-License-Identifier: MIT
// Launch helpers shared by the neighbour passes' files (substep_kernels.cu, density_kernels.cu):
// the lane groups' dispatch over G and their grid sizes.
#pragma once

#include <stdint.h>

#include <type_traits>

namespace sph {
namespace lanes {

// The thread's index in the grid (64 bits: n particles of G lanes can pass 2^32 threads).
__device__ __forceinline__ unsigned long long grid_thread() {
  return static_cast<unsigned long long>(blockIdx.x) * blockDim.x + threadIdx.x;
}

// Calls launch(std::integral_constant<unsigned, G>) for the lane group G = lanes (1, 2, 4, 8).
template <class Launch>
inline void with_lanes(unsigned lanes, Launch&& launch) {
  switch (lanes) {
    case 2:
      launch(std::integral_constant<unsigned, 2>{});
      break;
    case 4:
      launch(std::integral_constant<unsigned, 4>{});
      break;
    case 8:
      launch(std::integral_constant<unsigned, 8>{});
      break;
    default:
      launch(std::integral_constant<unsigned, 1>{});
      break;
  }
}

// Blocks for n particles of `lanes` threads each.
inline unsigned blocks_for_lanes(uint32_t n, unsigned lanes, unsigned threads) {
  const uint64_t items = static_cast<uint64_t>(n) * lanes;
  return items == 0 ? 1u : static_cast<unsigned>((items + threads - 1) / threads);
}

}  // namespace lanes
}  // namespace sph
