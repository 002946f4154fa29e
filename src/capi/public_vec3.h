// SPDX-License-Identifier: MIT
// The C API's sph_vec3 and the library's Vec3, one way and the other: one definition for every
// api_*.cpp that passes vectors (loads, probes, particles, scenes).
#pragma once

#include "../physics/vec3.h"
#include "sph_c.h"

namespace sph {

inline sph_vec3 to_public(const Vec3& v) { return sph_vec3{v.x, v.y, v.z}; }
inline Vec3 vec3_from_public(const sph_vec3& v) { return Vec3{v.x, v.y, v.z}; }

}  // namespace sph
