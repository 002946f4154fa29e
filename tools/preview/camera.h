// SPDX-License-Identifier: MIT
// A pinhole camera for the preview: world points to pixels and pixels to rays.
#ifndef SPH_TOOLS_CAMERA_H
#define SPH_TOOLS_CAMERA_H

#include <cstdint>

#include "sph_c.h"

namespace sph_tools {

struct Camera {
  sph_vec3 eye{}, forward{}, right{}, up{};  // orthonormal; forward points into the image
  float focal = 1.0f;                        // pixels
  uint32_t width = 0, height = 0;

  static Camera look_at(sph_vec3 eye, sph_vec3 target, sph_vec3 up, float fov_degrees, uint32_t width,
                        uint32_t height);
  // A camera that looks at the box [lo, hi] from the front, above and to the right, with the
  // whole box in view.
  static Camera framing(sph_vec3 lo, sph_vec3 hi, float fov_degrees, uint32_t width, uint32_t height);

  // Pixel coordinates (x right, y down; pixel centres at +0.5) and the depth along forward.
  // False when the point is behind the camera.
  bool project(sph_vec3 p, float* px, float* py, float* depth) const;
  // The unit direction of the ray through pixel coordinates (px, py).
  sph_vec3 ray(float px, float py) const;
};

}  // namespace sph_tools

#endif
