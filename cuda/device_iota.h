// SPDX-License-Identifier: MIT
// The identity permutation on the device, for the halo tables' sorts.
#pragma once

#include <cuda_runtime.h>
#include <stdint.h>

namespace sph {

// Writes v[i] = i for i < n (enqueued on the world's stream, never the legacy default stream,
// which would wait for an engine's blocking streams; a failed launch throws as check_launch does).
void fill_iota(uint32_t* v, uint32_t n, cudaStream_t stream);

}  // namespace sph
