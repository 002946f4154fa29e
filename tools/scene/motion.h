// SPDX-License-Identifier: MIT
// Motion: a pose over time from keyframes, sampled once per frame and handed to the library
// as the next target transform (sph_collider_set_target_transform).
#ifndef SPH_TOOLS_MOTION_H
#define SPH_TOOLS_MOTION_H

#include <vector>

#include "sph_c.h"

namespace sph_tools {

struct Keyframe {
  double time = 0.0;  // s, increasing
  sph_transform transform{};
};

struct Motion {
  enum class Interpolation {
    kLinear,  // positions linearly, rotations by slerp
    kSmooth,  // positions by a Catmull-Rom spline through the keys (C1), rotations by slerp
  };
  std::vector<Keyframe> keys;  // empty: no motion
  Interpolation interpolation = Interpolation::kLinear;
  bool loop = false;  // repeat [first key, last key] forever; otherwise hold the ends

  bool empty() const { return keys.empty(); }
  // The pose at time t (s). Requires !empty().
  sph_transform at(double t) const;
};

}  // namespace sph_tools

#endif
