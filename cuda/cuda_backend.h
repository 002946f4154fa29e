// Entry points of the CUDA backend, seen by the backend factory only.
#pragma once

#include <memory>

#include "../src/core/backend.h"

namespace sph {

// Devices the CUDA runtime reports (0 on any error: no driver, no device).
int cuda_usable_device_count();

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig& config, int device_ordinal);

}  // namespace sph

namespace sph {

// Copies `bytes` from device memory of `device_ordinal` into host memory (synchronous); for
// inputs the caller gives in device memory (SDF grids). Throws Error(Device) on failure.
void cuda_copy_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal);

}  // namespace sph
