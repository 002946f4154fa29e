// SPDX-License-Identifier: MIT
// The generic target of the SIMD passes: 16 lanes of plain floats, for any processor (the
// compiler vectorises what it can for the build's baseline). It computes the same bits as the
// x86 targets and is their reference in tests/unit/test_simd_passes.cpp.
#include "cpu_simd_gathers.h"

namespace sph {
namespace {
struct GenericTarget {};
using GenericLanes = simd::Lanes<float, simd::kLaneCount, GenericTarget>;
}  // namespace

extern const SimdPasses kSimdPassesGeneric =
    simd::make_simd_passes<GenericLanes>(SimdTarget::Generic, "generic");

}  // namespace sph
