// SPDX-License-Identifier: MIT
// Marks a function callable from host and device code: one formula for both backends.
#pragma once

#if defined(__CUDACC__)
#define SPH_HD __host__ __device__ __forceinline__
#else
#define SPH_HD inline
#endif

// Asks nvcc to unroll the next loop n times; nothing for host compilers (g++ would warn about
// an unknown pragma). Never changes what a loop computes.
#if defined(__CUDACC__)
#define SPH_PRAGMA(x) _Pragma(#x)
#define SPH_UNROLL(n) SPH_PRAGMA(unroll n)
#else
#define SPH_UNROLL(n)
#endif

namespace sph {

// a / b rounded as IEEE 754 divides, on the host and on the device whatever the file's nvcc flags
// (-prec-div=false makes `/` approximate): for a value that a host-driven loop and a device kernel
// must compute to the same bits (a solve's stopping bound, physics/dfsph.h). Normal operands and
// quotients only: under -ftz=true the device flushes subnormal ones to zero, the host does not.
SPH_HD float ieee_divide(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fdiv_rn(a, b);
#else
  return a / b;
#endif
}

}  // namespace sph
