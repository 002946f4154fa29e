// SPDX-License-Identifier: MIT
#include "camera.h"

#include <algorithm>
#include <cmath>

#include "geometry.h"

namespace sph_tools {

Camera Camera::look_at(sph_vec3 eye, sph_vec3 target, sph_vec3 up, float fov_degrees, uint32_t width,
                       uint32_t height) {
  Camera c;
  c.eye = eye;
  c.forward = normalize(target - eye);
  sph_vec3 right = cross(c.forward, up);
  if (length(right) < 1e-6f)
    right = cross(c.forward, std::fabs(c.forward.x) < 0.9f ? v3(1, 0, 0) : v3(0, 0, 1));
  c.right = normalize(right);
  c.up = cross(c.right, c.forward);
  c.width = width;
  c.height = height;
  c.focal = 0.5f * static_cast<float>(height) / std::tan(0.5f * fov_degrees * 3.14159265f / 180.0f);
  return c;
}

Camera Camera::framing(sph_vec3 lo, sph_vec3 hi, float fov_degrees, uint32_t width, uint32_t height) {
  const sph_vec3 center = (lo + hi) * 0.5f;
  const sph_vec3 toward_eye = normalize(v3(0.45f, 0.5f, 1.0f));
  Camera c = look_at(center + toward_eye, center, v3(0, 1, 0), fov_degrees, width, height);
  // Distance so that every corner of the box falls within 92 % of the image.
  const float tan_y = 0.46f * static_cast<float>(height) / c.focal;
  const float tan_x = 0.46f * static_cast<float>(width) / c.focal;
  float distance = 0.05f;
  for (int k = 0; k < 8; ++k) {
    const sph_vec3 corner = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    const sph_vec3 q = corner - center;
    const float along = dot(q, toward_eye);  // toward the camera
    distance = std::max(distance, along + std::fabs(dot(q, c.right)) / tan_x);
    distance = std::max(distance, along + std::fabs(dot(q, c.up)) / tan_y);
  }
  c.eye = center + toward_eye * distance;
  return c;
}

bool Camera::project(sph_vec3 p, float* px, float* py, float* depth) const {
  const sph_vec3 q = p - eye;
  const float z = dot(q, forward);
  if (z <= 1e-4f) return false;
  *px = 0.5f * static_cast<float>(width) + focal * dot(q, right) / z;
  *py = 0.5f * static_cast<float>(height) - focal * dot(q, up) / z;
  *depth = z;
  return true;
}

sph_vec3 Camera::ray(float px, float py) const {
  const float x = (px - 0.5f * static_cast<float>(width)) / focal;
  const float y = (0.5f * static_cast<float>(height) - py) / focal;
  return normalize(forward + right * x + up * y);
}

}  // namespace sph_tools
