// SPDX-License-Identifier: MIT
// Packed 16-byte particle records shared by both backends. The w slot carries a second
// quantity so that one 16-byte load brings everything a neighbour contributes.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "vec3.h"

namespace sph {

// Layout-compatible with CUDA's float4 (16-byte aligned x, y, z, w).
struct alignas(16) Float4 {
  float x, y, z, w;
};

SPH_HD Vec3 xyz(const Float4& v) { return Vec3{v.x, v.y, v.z}; }
SPH_HD Float4 make_float4_record(Vec3 v, float w) { return Float4{v.x, v.y, v.z, w}; }

}  // namespace sph
