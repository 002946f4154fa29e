// SPDX-License-Identifier: MIT
// Small helpers shared by the kernel launch sites.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "cuda_status.h"

namespace sph {

constexpr unsigned kDefaultBlockSize = 256;

// Blocks to cover n items; at least one, so a world with no particles still launches (every
// kernel bounds-checks its index) and the frame bookkeeping runs as on the CPU.
inline unsigned blocks_for(uint32_t n, unsigned threads) {
  return n == 0 ? 1u : static_cast<unsigned>((static_cast<uint64_t>(n) + threads - 1) / threads);
}

// Reports a failed launch (bad configuration, or a sticky error from earlier work).
inline void check_launch(const char* kernel) { cuda_check(cudaGetLastError(), kernel); }

}  // namespace sph
