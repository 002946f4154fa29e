// SPDX-License-Identifier: MIT
// Colours and lighting of the preview: the speed colour ramp, the light, the background and
// the depth fade shared by particles and surfaces.
#ifndef SPH_TOOLS_SHADING_H
#define SPH_TOOLS_SHADING_H

#include <algorithm>
#include <cmath>

#include "geometry.h"

namespace sph_tools {

struct Rgb {
  float r, g, b;
};

// Deep blue at rest, through cyan, to near white at speed_max and above.
inline Rgb speed_color(float speed, float speed_max) {
  const float t = std::clamp(speed / speed_max, 0.0f, 1.0f);
  const Rgb stops[3] = {{0.02f, 0.12f, 0.45f}, {0.05f, 0.45f, 0.85f}, {0.80f, 0.95f, 1.0f}};
  const float u = t * 2.0f;
  const int i = std::min(1, static_cast<int>(u));
  const float f = u - static_cast<float>(i);
  return Rgb{stops[i].r + (stops[i + 1].r - stops[i].r) * f, stops[i].g + (stops[i + 1].g - stops[i].g) * f,
             stops[i].b + (stops[i + 1].b - stops[i].b) * f};
}

// Background: a dark vertical gradient.
inline Rgb background(float v) {  // v: 0 at the top, 1 at the bottom
  return Rgb{0.045f - 0.025f * v, 0.050f - 0.027f * v, 0.065f - 0.032f * v};
}

// Lambert plus ambient plus a soft highlight for a unit normal n seen along view (unit, from
// the eye), with the light in camera space.
inline float lighting(sph_vec3 n, sph_vec3 to_eye, sph_vec3 light) {
  const float diffuse = std::max(0.0f, dot(n, light));
  const sph_vec3 half = normalize(light + to_eye);
  const float specular = std::pow(std::max(0.0f, dot(n, half)), 40.0f);
  return 0.28f + 0.72f * diffuse + 0.35f * specular;
}

// Farther things fade toward the background: 0 at near, up to 0.5 at far.
inline float depth_fade(float depth, float near_depth, float far_depth) {
  return 0.5f * std::clamp((depth - near_depth) / std::max(1e-6f, far_depth - near_depth), 0.0f, 1.0f);
}

}  // namespace sph_tools

#endif
