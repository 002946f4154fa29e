// SPDX-License-Identifier: MIT
// The AVX2 target of the SIMD passes: 16 lanes as two 8-float registers. Built with -mavx2
// (CMakeLists.txt) and run only where the processor has AVX2 (cpu_simd_dispatch.cpp).
#include "cpu_simd_gathers.h"
#include "cpu_simd_xsimd.h"

namespace sph {
namespace {
struct Avx2Target {};
using Avx2Lanes = simd::Lanes<xsimd::batch<float, xsimd::avx2>, 2, Avx2Target>;
}  // namespace

extern const SimdPasses kSimdPassesAvx2 = simd::make_simd_passes<Avx2Lanes>(SimdTarget::Avx2, "avx2");

}  // namespace sph
