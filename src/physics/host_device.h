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
