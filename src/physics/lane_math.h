// SPDX-License-Identifier: MIT
// The scalar half of the lane vocabulary in which the pair formulas are written once for both a
// scalar (float, or double for the lattice calibration) and a pack of SIMD lanes (the CPU
// backend's src/cpu/cpu_simd_lanes.h). A formula's condition is a value, not a branch:
// select(c, a, b) is `c ? a : b` for a scalar and a per-lane blend for lanes, so one text serves
// both. Both sides are evaluated, which is harmless here: no formula traps, and a discarded
// lane's inf or NaN never reaches a sum. For a scalar every result is bit for bit that of the
// branch it replaces, as long as the condition keeps the branch's own comparison (`r >= h`
// selecting zero, not `r < h` selecting the value: the two differ for NaN).
#pragma once

#include "host_device.h"

#if defined(__CUDACC__)
#define SPH_SQRTF sqrtf
#else
#include <cmath>
#define SPH_SQRTF std::sqrt
#endif

namespace sph {

SPH_HD float select(bool c, float a, float b) { return c ? a : b; }
SPH_HD double select(bool c, double a, double b) { return c ? a : b; }

SPH_HD float square_root(float x) { return SPH_SQRTF(x); }
#if defined(__CUDACC__)
SPH_HD double square_root(double x) { return sqrt(x); }
#else
SPH_HD double square_root(double x) { return std::sqrt(x); }
#endif

}  // namespace sph
