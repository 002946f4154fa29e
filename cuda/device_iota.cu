// SPDX-License-Identifier: MIT
#include "device_iota.h"

#include "kernel_launch.h"

namespace sph {
namespace {

__global__ void iota_kernel(uint32_t* v, uint32_t n) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) v[i] = i;
}

}  // namespace

void fill_iota(uint32_t* v, uint32_t n, cudaStream_t stream) {
  iota_kernel<<<blocks_for(n, kDefaultBlockSize), kDefaultBlockSize, 0, stream>>>(v, n);
  check_launch("iota_kernel");
}

}  // namespace sph
