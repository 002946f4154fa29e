// Marks a function callable from host and device code: one formula for both backends.
#pragma once

#if defined(__CUDACC__)
#define SPH_HD __host__ __device__ __forceinline__
#else
#define SPH_HD inline
#endif
