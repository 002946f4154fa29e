// SPDX-License-Identifier: MIT
#include "kernel_radius_rule.h"

#include <cfloat>

#include "fcc_lattice.h"

namespace sph {

const char* kernel_radius_fault(float particle_spacing, float kernel_radius) {
  if (kernel_radius < particle_spacing) return "is smaller than the particle spacing";
  // Within float rounding of 5 x spacing, as written: 0.1f for 0.02f lies one float step above
  // 5.0f * 0.02f = 0.099999994f.
  if (static_cast<double>(kernel_radius) >
      static_cast<double>(kMaxKernelRadiusFactor) * particle_spacing * (1.0 + 4.0 * FLT_EPSILON))
    return "is more than 5 x the particle spacing (hundreds of neighbours per particle)";
  // At h = spacing (and a few float steps above it) the lattice's nearest neighbours sit on the
  // kernel's edge, where W_spiky and its moment vanish: the lattice scale divides by (nearly)
  // zero and every filled particle's density was non-finite at the first step (one float step
  // above: a scale of 3e12). 1e9 (h about 1.000003 spacings) leaves a margin below the largest
  // scale measured to step finitely (5e10, eight steps above); 1.8 spacings give 1.11.
  constexpr float kMaxSpikyScale = 1e9f;
  if (!(fcc_spiky_scale(particle_spacing, kernel_radius) <= kMaxSpikyScale))
    return "is too close to the particle spacing: the lattice's nearest neighbours lie on the kernel's edge";
  return nullptr;
}

}  // namespace sph
