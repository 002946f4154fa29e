// SPDX-License-Identifier: MIT
// The AVX-512 target of the SIMD passes: 16 lanes as one 16-float register. Built with
// -mavx512f (CMakeLists.txt) and run only where the processor has AVX-512F
// (cpu_simd_dispatch.cpp).
#include "cpu_simd_gathers.h"
#include "cpu_simd_xsimd.h"

namespace sph {
namespace {
struct Avx512Target {};
using Avx512Lanes = simd::Lanes<xsimd::batch<float, xsimd::avx512f>, 1, Avx512Target>;
}  // namespace

extern const SimdPasses kSimdPassesAvx512 = simd::make_simd_passes<Avx512Lanes>(SimdTarget::Avx512, "avx512");

}  // namespace sph
