// SPDX-License-Identifier: MIT
// Copies caller data that lives in device memory (SDF grids given as SPH_MEMORY_CUDA_DEVICE)
// to the host, on the context's device, restoring the caller's current device.
#include <cuda_runtime.h>

#include <string>

#include "../src/core/status.h"
#include "cuda_backend.h"

namespace sph {

void cuda_copy_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal) {
  int previous = 0;
  if (cudaGetDevice(&previous) != cudaSuccess) previous = -1;
  cudaError_t status = cudaSetDevice(device_ordinal);
  if (status == cudaSuccess) status = cudaMemcpy(host_dst, device_src, bytes, cudaMemcpyDeviceToHost);
  if (previous >= 0) cudaSetDevice(previous);
  if (status != cudaSuccess) {
    cudaGetLastError();  // clear a non-sticky error so later calls are not affected
    throw Error(Status::Device,
                std::string("memory: copying device data to the host failed: ") + cudaGetErrorString(status));
  }
}

}  // namespace sph
