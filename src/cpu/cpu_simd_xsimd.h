// SPDX-License-Identifier: MIT
// The parts of a lane pack as xsimd registers (xsimd 8, Debian's libxsimd-dev): included only by
// the target files built for that instruction set (cpu_simd_target_avx2.cpp,
// cpu_simd_target_avx512.cpp), which xsimd compiles for by the compiler's -m flags.
#pragma once

#include <xsimd/xsimd.hpp>

#include <type_traits>

#include "cpu_simd_lanes.h"

namespace sph {
namespace simd {

template <class Arch>
struct PartOps<xsimd::batch<float, Arch>> {
  using Batch = xsimd::batch<float, Arch>;
  using Bool = xsimd::batch_bool<float, Arch>;
  static Batch select(const Bool& c, const Batch& a, const Batch& b) { return xsimd::select(c, a, b); }
  static Batch sqrt(const Batch& x) {
#if defined(__AVX512F__)
    // xsimd's _mm512_sqrt_ps trips GCC 12's -Wmaybe-uninitialized (its undefined pass-through
    // register); the all-lanes masked form is the same instruction.
    if constexpr (std::is_same<Arch, xsimd::avx512f>::value) return Batch(_mm512_mask_sqrt_ps(x, 0xffff, x));
#endif
    return xsimd::sqrt(x);
  }
  static Batch load(const float* p) { return Batch::load_unaligned(p); }
  static void store(const Batch& part, float* p) { part.store_unaligned(p); }
  static Bool both(const Bool& a, const Bool& b) { return a && b; }
  static Bool either(const Bool& a, const Bool& b) { return a || b; }
  static Bool negate(const Bool& a) { return !a; }
  static bool any(const Bool& a) { return xsimd::any(a); }
};

}  // namespace simd
}  // namespace sph
