// SPDX-License-Identifier: MIT
// Picks the SIMD passes' target for the processor at run time (cpu_simd_passes.h). The x86
// targets exist in x86-64 builds (SPH_SIMD_X86, CMakeLists.txt); the generic one everywhere.
#include "cpu_simd_passes.h"

namespace sph {

const SimdPasses* simd_passes_built(SimdTarget target) {
#if defined(SPH_SIMD_X86)
  if (target == SimdTarget::Avx2) return &kSimdPassesAvx2;
  if (target == SimdTarget::Avx512) return &kSimdPassesAvx512;
#endif
  return target == SimdTarget::Generic ? &kSimdPassesGeneric : nullptr;
}

bool simd_target_runs(SimdTarget target) {
  if (simd_passes_built(target) == nullptr) return false;
#if defined(SPH_SIMD_X86)
  // GCC's checks read CPUID and whether the operating system saves the wider registers (XCR0).
  __builtin_cpu_init();
  if (target == SimdTarget::Avx2) return __builtin_cpu_supports("avx2");
  if (target == SimdTarget::Avx512) return __builtin_cpu_supports("avx512f");
#endif
  return target == SimdTarget::Generic;
}

const SimdPasses& best_simd_passes() {
  static const SimdPasses* best = [] {
    for (SimdTarget t : {SimdTarget::Avx512, SimdTarget::Avx2})
      if (simd_target_runs(t)) return simd_passes_built(t);
    return simd_passes_built(SimdTarget::Generic);
  }();
  return *best;
}

}  // namespace sph
