// SPDX-License-Identifier: MIT
// Particles drawn as shaded spheres (screen-space splats with a per-pixel sphere depth),
// coloured by speed and faded with depth.
#ifndef SPH_TOOLS_PARTICLE_SPLAT_H
#define SPH_TOOLS_PARTICLE_SPLAT_H

#include <cstdint>

#include "camera.h"
#include "image.h"

namespace sph_tools {

struct SplatStyle {
  float radius = 0.01f;                       // m
  float speed_max = 2.0f;                     // m/s drawn brightest
  float near_depth = 0.0f, far_depth = 1.0f;  // the depth fade's range
};

// positions and velocities: 3 floats per particle.
void splat_particles(const float* positions, const float* velocities, uint32_t count, const Camera& camera,
                     const SplatStyle& style, Image* image);

}  // namespace sph_tools

#endif
