// SPDX-License-Identifier: MIT
// gpu_check_mpi_device_lost's one CUDA part: a sticky device error in this process (an illegal
// address in a kernel of the caller's, which poisons the process's context, as
// tests/gpu/check_device_lost.cu does), and the event a rank records on its world after it.
#include <cuda_runtime.h>

#include "mpi_poison_device.h"

namespace {
__global__ void write_to_nowhere(int* p) { p[threadIdx.x] = 1; }
}  // namespace

extern "C" void* mpi_device_event_create(void) {
  cudaEvent_t event = nullptr;
  return cudaEventCreateWithFlags(&event, cudaEventDisableTiming) == cudaSuccess ? event : nullptr;
}

extern "C" int mpi_poison_device(void) {
  write_to_nowhere<<<1, 32>>>(reinterpret_cast<int*>(0x10));
  return cudaDeviceSynchronize() != cudaSuccess;
}
