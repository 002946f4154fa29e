// SPDX-License-Identifier: MIT
#include "collider_overlay.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "geometry.h"

namespace sph_tools {

namespace {

// Light direction (world), from the upper left front.
const sph_vec3 kLight = normalize(v3(-0.4f, 0.8f, 0.45f));

// Runs body(y) for every row, spread over the hardware threads.
template <typename F>
void for_rows(uint32_t height, F body) {
  const unsigned threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([=] {
      for (uint32_t y = t; y < height; y += threads) body(y);
    });
  for (std::thread& th : pool) th.join();
}

// The parameter range [t0, t1] where a ray is inside the box [lo, hi].
bool clip_box(sph_vec3 o, sph_vec3 d, sph_vec3 lo, sph_vec3 hi, float* t0, float* t1) {
  const float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z}, l[3] = {lo.x, lo.y, lo.z},
              h[3] = {hi.x, hi.y, hi.z};
  float a = 0.0f, b = 1e30f;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(dd[i]) < 1e-12f) {
      if (oo[i] < l[i] || oo[i] > h[i]) return false;
      continue;
    }
    float u = (l[i] - oo[i]) / dd[i], v = (h[i] - oo[i]) / dd[i];
    if (u > v) std::swap(u, v);
    a = std::max(a, u);
    b = std::min(b, v);
  }
  *t0 = a;
  *t1 = b;
  return a < b;
}

}  // namespace

float ColliderOverlay::Grid::sample(sph_vec3 p) const {
  const float g[3] = {(p.x - origin.x) / cell, (p.y - origin.y) / cell, (p.z - origin.z) / cell};
  int i[3];
  float f[3];
  float outside = 0.0f;
  for (int a = 0; a < 3; ++a) {
    const float c = std::clamp(g[a], 0.0f, static_cast<float>(n[a] - 1));
    outside += (g[a] - c) * (g[a] - c);
    i[a] = std::min(static_cast<int>(c), n[a] - 2);
    f[a] = c - static_cast<float>(i[a]);
  }
  auto at = [&](int x, int y, int z) {
    return d[static_cast<size_t>(x) + n[0] * (y + static_cast<size_t>(n[1]) * z)];
  };
  const float c00 = at(i[0], i[1], i[2]) * (1 - f[0]) + at(i[0] + 1, i[1], i[2]) * f[0];
  const float c10 = at(i[0], i[1] + 1, i[2]) * (1 - f[0]) + at(i[0] + 1, i[1] + 1, i[2]) * f[0];
  const float c01 = at(i[0], i[1], i[2] + 1) * (1 - f[0]) + at(i[0] + 1, i[1], i[2] + 1) * f[0];
  const float c11 = at(i[0], i[1] + 1, i[2] + 1) * (1 - f[0]) + at(i[0] + 1, i[1] + 1, i[2] + 1) * f[0];
  const float v = (c00 * (1 - f[1]) + c10 * f[1]) * (1 - f[2]) + (c01 * (1 - f[1]) + c11 * f[1]) * f[2];
  return v + std::sqrt(outside) * cell;
}

void ColliderOverlay::add(const sph_sdf* sdf, sph_vec3 lo, sph_vec3 hi, float cell, bool moving) {
  Collider c;
  c.moving = moving;
  // At most 256 cells along the longest side: the overlay is faint, not exact. A margin of two
  // cells keeps surfaces on the box's faces inside the grid.
  const sph_vec3 extent0 = hi - lo;
  cell = std::max(cell, std::max(extent0.x, std::max(extent0.y, extent0.z)) / 256.0f);
  lo = lo - v3(2 * cell, 2 * cell, 2 * cell);
  hi = hi + v3(2 * cell, 2 * cell, 2 * cell);
  const sph_vec3 size = hi - lo;
  c.grid.cell = cell;
  c.grid.origin = lo;
  const float extent[3] = {size.x, size.y, size.z};
  for (int a = 0; a < 3; ++a) c.grid.n[a] = std::max(2, static_cast<int>(std::ceil(extent[a] / cell)) + 1);
  c.grid.d.resize(static_cast<size_t>(c.grid.n[0]) * c.grid.n[1] * c.grid.n[2]);
  for (int k = 0; k < c.grid.n[2]; ++k)
    for (int j = 0; j < c.grid.n[1]; ++j)
      for (int i = 0; i < c.grid.n[0]; ++i) {
        const sph_vec3 p =
            lo + v3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)) * cell;
        float d = 0.0f;
        if (sph_sdf_sample(sdf, p, &d) < 0) d = 1e3f;
        c.grid.d[static_cast<size_t>(i) + c.grid.n[0] * (j + static_cast<size_t>(c.grid.n[1]) * k)] = d;
      }
  colliders_.push_back(std::move(c));
  static_traced_ = false;
}

void ColliderOverlay::trace_one(const Collider& c, const sph_transform& pose, const Camera& camera,
                                Rows* rows) const {
  const Grid& g = c.grid;
  const sph_vec3 lo = g.origin;
  const sph_vec3 hi = g.origin + v3(static_cast<float>(g.n[0] - 1), static_cast<float>(g.n[1] - 1),
                                    static_cast<float>(g.n[2] - 1)) *
                                     g.cell;
  const sph_quat to_local_rotation = quat_conjugate(quat_normalize(pose.rotation));
  const sph_vec3 origin = to_local(pose, camera.eye);
  const float min_step = 0.35f * g.cell;
  for_rows(camera.height, [&](uint32_t y) {
    std::vector<Crossing>& row = (*rows)[y];
    for (uint32_t x = 0; x < camera.width; ++x) {
      const sph_vec3 world_dir = camera.ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      const sph_vec3 dir = rotate(to_local_rotation, world_dir);
      float t0, t1;
      if (!clip_box(origin, dir, lo, hi, &t0, &t1)) continue;
      const float cos_view = dot(world_dir, camera.forward);
      float t = t0, d = g.sample(origin + dir * t);
      for (int steps = 0; t < t1 && steps < 512; ++steps) {
        const float t_next = t + std::max(0.8f * std::fabs(d), min_step);
        const float d_next = g.sample(origin + dir * t_next);
        if ((d < 0.0f) != (d_next < 0.0f)) {
          // Refine the crossing by bisection, then shade it from the gradient.
          float a = t, b = t_next, da = d;
          for (int k = 0; k < 6; ++k) {
            const float m = 0.5f * (a + b), dm = g.sample(origin + dir * m);
            if ((dm < 0.0f) == (da < 0.0f)) {
              a = m;
              da = dm;
            } else {
              b = m;
            }
          }
          const float tc = 0.5f * (a + b);
          const sph_vec3 p = origin + dir * tc;
          const float e = 0.5f * g.cell;
          const sph_vec3 n_local = normalize(v3(g.sample(p + v3(e, 0, 0)) - g.sample(p - v3(e, 0, 0)),
                                                g.sample(p + v3(0, e, 0)) - g.sample(p - v3(0, e, 0)),
                                                g.sample(p + v3(0, 0, e)) - g.sample(p - v3(0, 0, e))));
          const sph_vec3 n = rotate(quat_normalize(pose.rotation), n_local);
          const float facing = std::fabs(dot(n, world_dir));
          const float rim = std::pow(1.0f - facing, 3.0f);
          Crossing cr;
          cr.x = x;
          cr.depth = tc * cos_view;
          cr.alpha = 0.07f + 0.5f * rim;
          cr.shade = 0.55f + 0.45f * std::fabs(dot(n, kLight));
          row.push_back(cr);
        }
        t = t_next;
        d = d_next;
      }
    }
  });
}

void ColliderOverlay::trace(const Camera& camera, const std::vector<sph_transform>& poses) {
  const bool any_moving =
      std::any_of(colliders_.begin(), colliders_.end(), [](const Collider& c) { return c.moving; });
  if (!static_traced_) {
    static_rows_.assign(camera.height, {});
    for (size_t i = 0; i < colliders_.size(); ++i)
      if (!colliders_[i].moving) trace_one(colliders_[i], poses[i], camera, &static_rows_);
    for (auto& row : static_rows_)
      std::stable_sort(row.begin(), row.end(),
                       [](const Crossing& a, const Crossing& b) { return a.x < b.x; });
    static_traced_ = true;
  }
  moving_rows_.assign(any_moving ? camera.height : 0, {});
  for (size_t i = 0; i < colliders_.size(); ++i)
    if (colliders_[i].moving) trace_one(colliders_[i], poses[i], camera, &moving_rows_);
  for (auto& row : moving_rows_)
    std::stable_sort(row.begin(), row.end(), [](const Crossing& a, const Crossing& b) { return a.x < b.x; });
}

void ColliderOverlay::composite(Image* image) const {
  std::vector<Crossing> here;
  for (uint32_t y = 0; y < image->height; ++y) {
    const std::vector<Crossing>* lists[2] = {y < static_rows_.size() ? &static_rows_[y] : nullptr,
                                             y < moving_rows_.size() ? &moving_rows_[y] : nullptr};
    size_t cursor[2] = {0, 0};
    for (uint32_t x = 0; x < image->width; ++x) {
      here.clear();
      for (int l = 0; l < 2; ++l) {
        if (!lists[l]) continue;
        while (cursor[l] < lists[l]->size() && (*lists[l])[cursor[l]].x == x)
          here.push_back((*lists[l])[cursor[l]++]);
      }
      if (here.empty()) continue;
      std::sort(here.begin(), here.end(),
                [](const Crossing& a, const Crossing& b) { return a.depth > b.depth; });
      const size_t pixel = static_cast<size_t>(y) * image->width + x;
      float* c = &image->rgb[3 * pixel];
      for (const Crossing& cr : here) {
        if (cr.depth >= image->depth[pixel]) continue;  // behind the fluid
        const float tint[3] = {0.80f * cr.shade, 0.84f * cr.shade, 0.90f * cr.shade};
        for (int k = 0; k < 3; ++k) c[k] = c[k] * (1.0f - cr.alpha) + tint[k] * cr.alpha;
      }
    }
  }
}

}  // namespace sph_tools
