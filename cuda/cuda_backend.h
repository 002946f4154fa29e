// Entry points of the CUDA backend, seen by the backend factory only.
#pragma once

#include <memory>

#include "../src/core/backend.h"

namespace sph {

// Devices the CUDA runtime reports (0 on any error: no driver, no device).
int cuda_usable_device_count();

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig& config, int device_ordinal);

}  // namespace sph
