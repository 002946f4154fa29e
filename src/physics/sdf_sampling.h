// SPDX-License-Identifier: MIT
// Sampling a dense signed-distance grid: trilinear values, the gradient of the trilinear
// field, and a conservative extension outside the grid. Samples sit at voxel centres with
// integer indices (OpenVDB's convention); local = index_to_local * (i, j, k, 1).
#pragma once

#include <stdint.h>

#include "grid_hash.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

// A row-major 3x4 affine map.
struct Affine3x4 {
  float m[12];
};

SPH_HD Vec3 apply_affine(const Affine3x4& a, Vec3 p) {
  return Vec3{a.m[0] * p.x + a.m[1] * p.y + a.m[2] * p.z + a.m[3],
              a.m[4] * p.x + a.m[5] * p.y + a.m[6] * p.z + a.m[7],
              a.m[8] * p.x + a.m[9] * p.y + a.m[10] * p.z + a.m[11]};
}

// Applies only the linear part (for directions and gradients).
SPH_HD Vec3 apply_linear(const Affine3x4& a, Vec3 v) {
  return Vec3{a.m[0] * v.x + a.m[1] * v.y + a.m[2] * v.z, a.m[4] * v.x + a.m[5] * v.y + a.m[6] * v.z,
              a.m[8] * v.x + a.m[9] * v.y + a.m[10] * v.z};
}

// Applies the transpose of the linear part: maps an index-space gradient to local space when
// a is the local-to-index map.
SPH_HD Vec3 apply_linear_transposed(const Affine3x4& a, Vec3 g) {
  return Vec3{a.m[0] * g.x + a.m[4] * g.y + a.m[8] * g.z, a.m[1] * g.x + a.m[5] * g.y + a.m[9] * g.z,
              a.m[2] * g.x + a.m[6] * g.y + a.m[10] * g.z};
}

struct SdfGridView {
  const float* distance;  // nx * ny * nz, i fastest; negative inside
  const Vec3* velocity;   // optional (null): surface velocity per voxel, local frame, m/s
  const float* friction;  // optional (null): friction coefficient per voxel
  int32_t nx, ny, nz;
  Affine3x4 local_to_index;  // inverse of the asset's index_to_local
  float min_voxel_size;      // smallest voxel edge in local units (for gradient steps)
};

// What the host knows of an SDF's slope (sdf_slope on the CPU backend, cpu_boundary_maps.h; none on
// the device), what lets the boundary map's rays skip samples (boundary_map.h):
// `bound`, a bound on the slope of sample_distance along any local direction (0: none known), and
// `cell_change`, at least the most its value can change across one voxel (the bound times a voxel's
// diagonal or more: sdf_slope takes three times the longest edge).
struct SdfSlope {
  float bound = 0.0f;
  float cell_change = 0.0f;
};

struct TrilinearCell {
  int32_t i, j, k;   // lower corner, clamped into the grid
  float fx, fy, fz;  // fractions in [0, 1]
  float outside;     // distance from the query to the grid's box, local units (0 inside)
};

// NaN clamps to lo: a NaN query point (inf - inf from an extreme but finite position or map)
// must still index inside the grid; the NaN it yields is caught as a non-finite step.
SPH_HD float clampf(float v, float lo, float hi) { return !(v >= lo) ? lo : (v > hi ? hi : v); }

SPH_HD TrilinearCell locate(const SdfGridView& g, Vec3 local) {
  const Vec3 idx = apply_affine(g.local_to_index, local);
  const float cx = clampf(idx.x, 0.0f, static_cast<float>(g.nx - 1));
  const float cy = clampf(idx.y, 0.0f, static_cast<float>(g.ny - 1));
  const float cz = clampf(idx.z, 0.0f, static_cast<float>(g.nz - 1));
  TrilinearCell c;
  c.i = g.nx > 1 ? static_cast<int32_t>(clampf(SPH_FLOORF(cx), 0.0f, static_cast<float>(g.nx - 2))) : 0;
  c.j = g.ny > 1 ? static_cast<int32_t>(clampf(SPH_FLOORF(cy), 0.0f, static_cast<float>(g.ny - 2))) : 0;
  c.k = g.nz > 1 ? static_cast<int32_t>(clampf(SPH_FLOORF(cz), 0.0f, static_cast<float>(g.nz - 2))) : 0;
  c.fx = g.nx > 1 ? cx - static_cast<float>(c.i) : 0.0f;
  c.fy = g.ny > 1 ? cy - static_cast<float>(c.j) : 0.0f;
  c.fz = g.nz > 1 ? cz - static_cast<float>(c.k) : 0.0f;
  // Distance to the box, measured in index units and converted with the smallest voxel edge:
  // a lower bound of the true local distance, so the extension never overstates clearance.
  const Vec3 d{idx.x - cx, idx.y - cy, idx.z - cz};
  c.outside = length(d) * g.min_voxel_size;
  return c;
}

template <class T>
SPH_HD T lerp_value(const T& a, const T& b, float s) {
  return a + (b - a) * s;
}

template <class T>
SPH_HD T trilinear(const T* data, const SdfGridView& g, const TrilinearCell& c) {
  const int32_t di = g.nx > 1 ? 1 : 0, dj = g.ny > 1 ? g.nx : 0, dk = g.nz > 1 ? g.nx * g.ny : 0;
  const int64_t base =
      static_cast<int64_t>(c.i) + static_cast<int64_t>(g.nx) * (c.j + static_cast<int64_t>(g.ny) * c.k);
  const T* p = data + base;
  const T x00 = lerp_value(p[0], p[di], c.fx);
  const T x10 = lerp_value(p[dj], p[dj + di], c.fx);
  const T x01 = lerp_value(p[dk], p[dk + di], c.fx);
  const T x11 = lerp_value(p[dk + dj], p[dk + dj + di], c.fx);
  return lerp_value(lerp_value(x00, x10, c.fy), lerp_value(x01, x11, c.fy), c.fz);
}

// Signed distance at a local point; outside the grid, the boundary value plus the distance to
// the grid's box (keeps the sign and grows away from the grid).
SPH_HD float sample_distance(const SdfGridView& g, Vec3 local) {
  const TrilinearCell c = locate(g, local);
  return trilinear(g.distance, g, c) + c.outside;
}

// Outward unit normal (normalised gradient) by central differences of the sampled field with
// a step of half the smallest voxel; zero where the field is flat.
SPH_HD Vec3 sample_normal(const SdfGridView& g, Vec3 local) {
  const float e = 0.5f * g.min_voxel_size;
  const Vec3 grad{
      sample_distance(g, local + Vec3{e, 0.0f, 0.0f}) - sample_distance(g, local - Vec3{e, 0.0f, 0.0f}),
      sample_distance(g, local + Vec3{0.0f, e, 0.0f}) - sample_distance(g, local - Vec3{0.0f, e, 0.0f}),
      sample_distance(g, local + Vec3{0.0f, 0.0f, e}) - sample_distance(g, local - Vec3{0.0f, 0.0f, e})};
  const float n = length(grad);
  return n > 0.0f ? grad * (1.0f / n) : Vec3{0.0f, 0.0f, 0.0f};
}

SPH_HD Vec3 sample_velocity(const SdfGridView& g, Vec3 local) {
  if (!g.velocity) return Vec3{0.0f, 0.0f, 0.0f};
  return trilinear(g.velocity, g, locate(g, local));
}

SPH_HD float sample_friction(const SdfGridView& g, Vec3 local, float fallback) {
  if (!g.friction) return fallback;
  return trilinear(g.friction, g, locate(g, local));
}

}  // namespace sph
