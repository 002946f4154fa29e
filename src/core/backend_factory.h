// The one place that knows which backends exist: picks the CPU or CUDA implementation.
#pragma once

#include <memory>

#include "backend.h"

namespace sph {

enum class BackendKind : uint32_t { Auto = 0, Cpu = 1, Cuda = 2 };

// Number of usable CUDA devices; 0 when the library was built without CUDA or none is present.
int cuda_device_count();
bool cuda_built();

// Resolves Auto to Cpu or Cuda. Throws Error(Unsupported) for Cuda without a device.
BackendKind resolve_backend(BackendKind requested, int device_ordinal);

// Copies caller data given in device memory to the host (CUDA builds only).
void copy_device_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal);

std::unique_ptr<Backend> make_backend(BackendKind kind, const WorldConfig& config, int device_ordinal,
                                      unsigned cpu_workers);

}  // namespace sph
