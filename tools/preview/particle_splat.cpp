// SPDX-License-Identifier: MIT
#include "particle_splat.h"

#include <algorithm>
#include <cmath>

#include "shading.h"

namespace sph_tools {

void splat_particles(const float* positions, const float* velocities, uint32_t count, const Camera& camera,
                     const SplatStyle& style, Image* image) {
  const sph_vec3 light = normalize(v3(-0.45f, 0.65f, 0.6f));  // camera space: x right, y up, z to the eye
  const sph_vec3 to_eye = v3(0.0f, 0.0f, 1.0f);
  const int w = static_cast<int>(image->width), h = static_cast<int>(image->height);
  for (uint32_t p = 0; p < count; ++p) {
    const sph_vec3 x = v3(positions[3 * p], positions[3 * p + 1], positions[3 * p + 2]);
    float cx, cy, depth;
    if (!camera.project(x, &cx, &cy, &depth) || depth <= style.radius) continue;
    const float r_px = std::max(0.75f, style.radius * camera.focal / depth);
    const int x0 = std::max(0, static_cast<int>(std::floor(cx - r_px))),
              x1 = std::min(w - 1, static_cast<int>(std::ceil(cx + r_px)));
    const int y0 = std::max(0, static_cast<int>(std::floor(cy - r_px))),
              y1 = std::min(h - 1, static_cast<int>(std::ceil(cy + r_px)));
    if (x0 > x1 || y0 > y1) continue;
    const sph_vec3 v = v3(velocities[3 * p], velocities[3 * p + 1], velocities[3 * p + 2]);
    const Rgb base = speed_color(length(v), style.speed_max);
    const float fade = depth_fade(depth, style.near_depth, style.far_depth);
    for (int py = y0; py <= y1; ++py)
      for (int px = x0; px <= x1; ++px) {
        const float dx = (static_cast<float>(px) + 0.5f - cx) / r_px,
                    dy = (static_cast<float>(py) + 0.5f - cy) / r_px;
        const float d2 = dx * dx + dy * dy;
        if (d2 > 1.0f) continue;
        const float nz = std::sqrt(1.0f - d2);
        const float z = depth - nz * style.radius;
        const size_t pixel = static_cast<size_t>(py) * image->width + static_cast<size_t>(px);
        if (z >= image->depth[pixel]) continue;
        image->depth[pixel] = z;
        const float shade = lighting(v3(dx, -dy, nz), to_eye, light);
        const Rgb bg = background(static_cast<float>(py) / static_cast<float>(h));
        float* c = &image->rgb[3 * pixel];
        c[0] = base.r * shade * (1.0f - fade) + bg.r * fade;
        c[1] = base.g * shade * (1.0f - fade) + bg.g * fade;
        c[2] = base.b * shade * (1.0f - fade) + bg.b * fade;
      }
  }
}

}  // namespace sph_tools
