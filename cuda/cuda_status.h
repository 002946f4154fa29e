// SPDX-License-Identifier: MIT
// CUDA errors as the library's Status codes, and the guard that keeps the caller's current
// device unchanged across every call into the backend.
#pragma once

#include <cuda_runtime.h>

#include "../src/core/status.h"

namespace sph {

// True for errors that leave the CUDA context unusable (illegal address, launch failure, ...):
// every later call in the process fails the same way.
bool cuda_error_is_sticky(cudaError_t error);

// The Status a failed CUDA call maps to: OutOfDeviceMemory for allocation failures,
// DeviceLost for sticky errors, Device for the rest.
Status status_of_cuda_error(cudaError_t error);

// Throws Error(status_of_cuda_error(error)) naming `what` unless error is cudaSuccess.
// Clears a non-sticky error from the runtime's last-error slot first, so it cannot resurface
// in an unrelated later check.
void cuda_check(cudaError_t error, const char* what);

// Sets the device for the scope and restores the caller's current device afterwards.
class DeviceGuard {
 public:
  explicit DeviceGuard(int device);
  ~DeviceGuard();
  DeviceGuard(const DeviceGuard&) = delete;
  DeviceGuard& operator=(const DeviceGuard&) = delete;

 private:
  int previous_ = -1;
  bool changed_ = false;
};

}  // namespace sph
