// SPDX-License-Identifier: MIT
// ParticleFrame: one frame's particle arrays, copied out of a world with
// sph_world_copy_attribute, in the world's order (match particles by id between frames).
#ifndef SPH_TOOLS_PARTICLE_FRAME_H
#define SPH_TOOLS_PARTICLE_FRAME_H

#include <cstdint>
#include <vector>

#include "sph_c.h"

namespace sph_tools {

struct ParticleFrame {
  uint32_t frame = 0;
  double time = 0.0;              // s
  float particle_spacing = 0.0f;  // m, the world's
  uint32_t count = 0;
  std::vector<float> position;  // 3 x count, m
  std::vector<float> velocity;  // 3 x count, m/s
  std::vector<float> density;   // count, kg/m^3
  std::vector<float> pressure;  // count
  std::vector<uint32_t> id;     // count
  bool has_user = false;        // the world carries a user attribute (SPH_FEATURE_USER_ATTRIBUTE)
  std::vector<uint32_t> user;   // count when has_user, else empty
};

// Copies every attribute of `world` into `out` (arrays are reused). Throws LibraryError.
void read_particles(const sph_world* world, uint32_t frame, double time, ParticleFrame* out);

}  // namespace sph_tools

#endif
