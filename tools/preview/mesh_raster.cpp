// SPDX-License-Identifier: MIT
#include "mesh_raster.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry.h"
#include "shading.h"

namespace sph_tools {

void raster_mesh(const SurfaceMesh& mesh, const Camera& camera, float near_depth, float far_depth,
                 Image* image) {
  const size_t nv = mesh.vertices.size() / 3;
  std::vector<sph_vec3> normal(nv, v3(0, 0, 0));
  auto vertex = [&](uint32_t i) {
    return v3(mesh.vertices[3 * i], mesh.vertices[3 * i + 1], mesh.vertices[3 * i + 2]);
  };
  for (size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    const uint32_t a = mesh.triangles[t], b = mesh.triangles[t + 1], c = mesh.triangles[t + 2];
    const sph_vec3 n = cross(vertex(b) - vertex(a), vertex(c) - vertex(a));  // area-weighted
    normal[a] = normal[a] + n;
    normal[b] = normal[b] + n;
    normal[c] = normal[c] + n;
  }
  struct Projected {
    float x, y, depth;
    bool ok;
  };
  std::vector<Projected> screen(nv);
  for (size_t i = 0; i < nv; ++i) {
    Projected& p = screen[i];
    p.ok = camera.project(vertex(static_cast<uint32_t>(i)), &p.x, &p.y, &p.depth);
    normal[i] = normalize(normal[i]);
  }
  const sph_vec3 light = normalize(v3(-0.4f, 0.8f, 0.45f));  // world space
  const Rgb water{0.06f, 0.32f, 0.70f};
  const int w = static_cast<int>(image->width), h = static_cast<int>(image->height);
  for (size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    const uint32_t idx[3] = {mesh.triangles[t], mesh.triangles[t + 1], mesh.triangles[t + 2]};
    const Projected& p0 = screen[idx[0]];
    const Projected& p1 = screen[idx[1]];
    const Projected& p2 = screen[idx[2]];
    if (!p0.ok || !p1.ok || !p2.ok) continue;
    const float area = (p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y);
    if (std::fabs(area) < 1e-12f) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p0.x, p1.x, p2.x}))));
    const int x1 = std::min(w - 1, static_cast<int>(std::ceil(std::max({p0.x, p1.x, p2.x}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p0.y, p1.y, p2.y}))));
    const int y1 = std::min(h - 1, static_cast<int>(std::ceil(std::max({p0.y, p1.y, p2.y}))));
    for (int py = y0; py <= y1; ++py)
      for (int px = x0; px <= x1; ++px) {
        const float sx = static_cast<float>(px) + 0.5f, sy = static_cast<float>(py) + 0.5f;
        const float w0 = ((p1.x - sx) * (p2.y - sy) - (p2.x - sx) * (p1.y - sy)) / area;
        const float w1 = ((p2.x - sx) * (p0.y - sy) - (p0.x - sx) * (p2.y - sy)) / area;
        const float w2 = 1.0f - w0 - w1;
        if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
        // Perspective-correct depth: interpolate 1/z.
        const float inv = w0 / p0.depth + w1 / p1.depth + w2 / p2.depth;
        const float z = 1.0f / inv;
        const size_t pixel = static_cast<size_t>(py) * image->width + static_cast<size_t>(px);
        if (z >= image->depth[pixel]) continue;
        image->depth[pixel] = z;
        const float b0 = w0 / p0.depth * z, b1 = w1 / p1.depth * z, b2 = w2 / p2.depth * z;
        sph_vec3 n = normalize(normal[idx[0]] * b0 + normal[idx[1]] * b1 + normal[idx[2]] * b2);
        const sph_vec3 to_eye = camera.ray(sx, sy) * -1.0f;
        if (dot(n, to_eye) < 0.0f) n = n * -1.0f;  // inside faces seen through a hole
        const float shade = lighting(n, to_eye, light);
        const float rim = std::pow(1.0f - std::max(0.0f, dot(n, to_eye)), 3.0f);
        const float fade = depth_fade(z, near_depth, far_depth);
        const Rgb bg = background(sy / static_cast<float>(h));
        float* c = &image->rgb[3 * pixel];
        c[0] = (water.r * shade + 0.35f * rim) * (1.0f - fade) + bg.r * fade;
        c[1] = (water.g * shade + 0.45f * rim) * (1.0f - fade) + bg.g * fade;
        c[2] = (water.b * shade + 0.55f * rim) * (1.0f - fade) + bg.b * fade;
      }
  }
}

}  // namespace sph_tools
