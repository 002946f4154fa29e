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

// Threads per block for `kernel` from the context's tuning (sph_context_def.cuda_density_block,
// cuda_force_block: 32..1024): the caller's choice where the kernel's registers let that many
// threads into one block, else the largest power of two that they do (a block of 512 or 1024
// threads of a kernel using 72-162 registers each asks for more than an SM's 64K registers, and
// every launch would fail). Any block of up to 256 threads fits (255 registers a thread at most),
// so the default asks the driver nothing. The results do not depend on the block size.
template <class Kernel>
unsigned fit_block(Kernel kernel, unsigned requested) {
  if (requested <= 256) return requested;
  cudaFuncAttributes attributes{};
  cuda_check(cudaFuncGetAttributes(&attributes, reinterpret_cast<const void*>(kernel)),
             "cudaFuncGetAttributes");
  unsigned fit = requested;
  while (fit > 256 && fit > static_cast<unsigned>(attributes.maxThreadsPerBlock)) fit /= 2;
  return fit;
}

}  // namespace sph
