// SPDX-License-Identifier: MIT
#include <string>

#include "cuda_status.h"

namespace sph {

bool cuda_error_is_sticky(cudaError_t error) {
  switch (error) {
    case cudaErrorIllegalAddress:
    case cudaErrorLaunchFailure:
    case cudaErrorLaunchTimeout:
    case cudaErrorHardwareStackError:
    case cudaErrorIllegalInstruction:
    case cudaErrorMisalignedAddress:
    case cudaErrorInvalidAddressSpace:
    case cudaErrorInvalidPc:
    case cudaErrorAssert:
    case cudaErrorECCUncorrectable:
    case cudaErrorNvlinkUncorrectable:
    case cudaErrorContextIsDestroyed:
    case cudaErrorDevicesUnavailable:
    case cudaErrorSystemNotReady:
    case cudaErrorUnknown:
      return true;
    default:
      return false;
  }
}

Status status_of_cuda_error(cudaError_t error) {
  if (error == cudaErrorMemoryAllocation) return Status::OutOfDeviceMemory;
  if (cuda_error_is_sticky(error)) return Status::DeviceLost;
  return Status::Device;
}

void cuda_check(cudaError_t error, const char* what) {
  if (error == cudaSuccess) return;
  // A non-sticky error stays in the runtime's last-error slot until read; read it here so a
  // later launch check does not report it again. A sticky error cannot be cleared.
  (void)cudaGetLastError();
  const Status status = status_of_cuda_error(error);
  std::string message =
      std::string(what) + ": " + cudaGetErrorName(error) + " (" + cudaGetErrorString(error) + ")";
  if (status == Status::DeviceLost) message += "; the device is lost for this process, destroy the world";
  throw Error(status, message);
}

DeviceGuard::DeviceGuard(int device) {
  if (cudaGetDevice(&previous_) != cudaSuccess) {
    (void)cudaGetLastError();
    previous_ = -1;
  }
  if (previous_ != device) {
    cuda_check(cudaSetDevice(device), "cudaSetDevice");
    changed_ = true;
  }
}

DeviceGuard::~DeviceGuard() {
  if (changed_ && previous_ >= 0 && cudaSetDevice(previous_) != cudaSuccess) (void)cudaGetLastError();
}

}  // namespace sph
