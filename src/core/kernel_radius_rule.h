// SPDX-License-Identifier: MIT
// The kernel radius a world takes beside its particle spacing. One rule for sph_world_create and
// the checkpoint reader, so that every world the library makes is one it loads again.
#pragma once

namespace sph {

// The largest kernel radius in particle spacings (hundreds of neighbours a particle beyond it).
constexpr float kMaxKernelRadiusFactor = 5.0f;

// Why a world cannot use kernel_radius with particle_spacing, as a phrase that follows the radius
// in a message ("is smaller than the particle spacing"), or nullptr when it can. Both positive.
const char* kernel_radius_fault(float particle_spacing, float kernel_radius);

}  // namespace sph
