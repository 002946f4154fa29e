// SPDX-License-Identifier: MIT
// Entry points of the CUDA backend, seen by the backend factory (src/factory) only.
#pragma once

#include <memory>

#include "../src/core/backend.h"

namespace sph {

// Devices the CUDA runtime reports (0 on any error: no driver, no device).
int cuda_usable_device_count();

// The backend's tuning (sph_context_def's cuda_* fields, checked by the C layer; docs/cuda.md).
// No choice changes results but particle_lanes (the order of the neighbour sums).
struct CudaBackendOptions {
  bool stream_frames = false;    // every frame on the stream driver (profilers, sanitizers)
  unsigned density_block = 128;  // threads per block of the density kernels (32..1024, powers of two)
  unsigned force_block = 128;    // threads per block of the force kernels
  unsigned particle_lanes = 0;   // lane groups (KernelTuning::particle_lanes): 0 = by particle count
  bool dfsph_masks = true;       // DFSPH's candidate masks (physics/neighbor_walk.h), 48 B a particle
  bool dfsph_lists = false;      // and its neighbour lists (needs the masks), 256 B a particle
};

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig& config, int device_ordinal,
                                           const CudaBackendOptions& options);

}  // namespace sph

namespace sph {

// Copies `bytes` from device memory of `device_ordinal` into host memory (synchronous); for
// inputs the caller gives in device memory (SDF grids). Throws Error(Device) on failure.
void cuda_copy_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal);

}  // namespace sph
