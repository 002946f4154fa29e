// SPDX-License-Identifier: MIT
#include "mesh_sdf.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "status.h"
#include "triangle_geometry.h"
#include "winding_number.h"

namespace sph {
namespace {

using V3 = Eigen::Vector3d;

HostVector<MeshTriangle> read_triangles(const MeshSpec& s, V3* low, V3* high) {
  require_argument(s.vertices != nullptr, "desc->vertices: is NULL (required)");
  require_argument(s.indices != nullptr, "desc->indices: is NULL (required)");
  require_argument(s.vertex_count >= 3,
                   "desc->vertex_count: " + std::to_string(s.vertex_count) + " is below 3");
  require_argument(
      s.index_count >= 3 && s.index_count % 3 == 0,
      "desc->index_count: " + std::to_string(s.index_count) + " is not a positive multiple of 3");
  require_argument(
      s.vertex_stride >= 3 * sizeof(float),
      "desc->vertex_stride: " + std::to_string(s.vertex_stride) + " is below 12 bytes (three floats)");
  HostVector<V3> points(s.vertex_count);
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(s.vertices);
  for (uint32_t i = 0; i < s.vertex_count; ++i) {
    float xyz[3];
    std::memcpy(xyz, bytes + static_cast<size_t>(i) * s.vertex_stride, sizeof xyz);
    require_argument(std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2]),
                     "desc->vertices[" + std::to_string(i) + "]: is not finite");
    points[i] = V3(xyz[0], xyz[1], xyz[2]);
  }
  *low = V3::Constant(INFINITY);
  *high = V3::Constant(-INFINITY);
  HostVector<MeshTriangle> triangles;
  triangles.reserve(s.index_count / 3);
  for (uint32_t t = 0; t < s.index_count / 3; ++t) {
    uint32_t corner[3];
    for (int k = 0; k < 3; ++k) {
      corner[k] = s.indices[3 * t + k];
      require_argument(corner[k] < s.vertex_count,
                       "desc->indices[" + std::to_string(3 * t + k) + "]: " + std::to_string(corner[k]) +
                           " is not below vertex_count " + std::to_string(s.vertex_count));
      *low = low->cwiseMin(points[corner[k]]);
      *high = high->cwiseMax(points[corner[k]]);
    }
    triangles.push_back(make_mesh_triangle(points[corner[0]], points[corner[1]], points[corner[2]]));
  }
  return triangles;
}

// The grid: voxel centres at integer indices, index (0, 0, 0) at origin.
struct Grid {
  int32_t n[3];
  V3 origin;
  double voxel;
  size_t at(int32_t i, int32_t j, int32_t k) const {
    return static_cast<size_t>(i) + static_cast<size_t>(n[0]) * (j + static_cast<size_t>(n[1]) * k);
  }
  V3 centre(int32_t i, int32_t j, int32_t k) const { return origin + voxel * V3(i, j, k); }
};

// Exact distances (and the closest triangle) for every voxel within `band` of a triangle.
void fill_band(const Grid& g, const HostVector<MeshTriangle>& triangles, double band,
               HostVector<float>& distance, HostVector<int32_t>& closest) {
  for (size_t t = 0; t < triangles.size(); ++t) {
    const MeshTriangle& tri = triangles[t];
    const V3 low = (tri.a.cwiseMin(tri.b).cwiseMin(tri.c) - g.origin).array() - band;
    const V3 high = (tri.a.cwiseMax(tri.b).cwiseMax(tri.c) - g.origin).array() + band;
    int32_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int32_t>(std::ceil(low[a] / g.voxel)));
      hi[a] = std::min(g.n[a] - 1, static_cast<int32_t>(std::floor(high[a] / g.voxel)));
    }
    // Voxels farther than the band from the triangle's plane are farther from the triangle:
    // the slab test skips most of its box before the closest-point search.
    const V3 normal = tri.degenerate ? V3::Zero() : V3((tri.b - tri.a).cross(tri.c - tri.a).normalized());
    for (int32_t k = lo[2]; k <= hi[2]; ++k)
      for (int32_t j = lo[1]; j <= hi[1]; ++j)
        for (int32_t i = lo[0]; i <= hi[0]; ++i) {
          const size_t v = g.at(i, j, k);
          const V3 p = g.centre(i, j, k);
          if (std::fabs(normal.dot(p - tri.a)) > band) continue;
          const double d = point_triangle_distance(p, tri);
          if (d < distance[v]) {
            distance[v] = static_cast<float>(d);
            closest[v] = static_cast<int32_t>(t);
          }
        }
  }
}

// The far field: two rounds of sweeps in the eight diagonal orders (Bridson's makelevelset3),
// each voxel taking the closest of its upwind neighbours' closest triangles. Distances stay
// exact point-triangle distances; only the triangle may be a near-best one far from the band.
void sweep_far_field(const Grid& g, const HostVector<MeshTriangle>& triangles, double band,
                     HostVector<float>& distance, HostVector<int32_t>& closest) {
  for (int round = 0; round < 2; ++round)
    for (int order = 0; order < 8; ++order) {
      const int di = (order & 1) ? -1 : 1, dj = (order & 2) ? -1 : 1, dk = (order & 4) ? -1 : 1;
      const int32_t i0 = di > 0 ? 1 : g.n[0] - 2, j0 = dj > 0 ? 1 : g.n[1] - 2, k0 = dk > 0 ? 1 : g.n[2] - 2;
      for (int32_t k = k0; k >= 0 && k < g.n[2]; k += dk)
        for (int32_t j = j0; j >= 0 && j < g.n[1]; j += dj)
          for (int32_t i = i0; i >= 0 && i < g.n[0]; i += di) {
            const size_t v = g.at(i, j, k);
            // Band voxels already hold their exact nearest distance.
            if (distance[v] <= band) continue;
            const int32_t candidates[7][3] = {
                {i - di, j, k},      {i, j - dj, k},      {i - di, j - dj, k},     {i, j, k - dk},
                {i - di, j, k - dk}, {i, j - dj, k - dk}, {i - di, j - dj, k - dk}};
            int32_t tried[7];
            int tried_count = 0;
            for (const auto& c : candidates) {
              if (c[0] < 0 || c[0] >= g.n[0] || c[1] < 0 || c[1] >= g.n[1] || c[2] < 0 || c[2] >= g.n[2])
                continue;
              const int32_t t = closest[g.at(c[0], c[1], c[2])];
              // Neighbours mostly share their triangle: each distinct one is measured once.
              if (t < 0 || t == closest[v] || std::find(tried, tried + tried_count, t) != tried + tried_count)
                continue;
              tried[tried_count++] = t;
              const double d = point_triangle_distance(g.centre(i, j, k), triangles[t]);
              if (d < distance[v]) {
                distance[v] = static_cast<float>(d);
                closest[v] = t;
              }
            }
          }
    }
}

// Negates the distance of every voxel inside. Voxels in the band get their own winding number;
// beyond the band no voxel edge crosses the surface (both ends lie farther than band >= one
// voxel from it), so each connected region outside the band takes the sign of its first voxel.
void apply_sign(const Grid& g, const HostVector<MeshTriangle>& triangles, double band,
                HostVector<float>& distance) {
  const WindingNumber winding(triangles);
  auto inside = [&](int32_t i, int32_t j, int32_t k) {
    return std::fabs(winding.at(g.centre(i, j, k))) >= 0.5;
  };
  HostVector<uint8_t> done(distance.size(), 0);
  HostVector<size_t> queue;
  for (int32_t k = 0; k < g.n[2]; ++k)
    for (int32_t j = 0; j < g.n[1]; ++j)
      for (int32_t i = 0; i < g.n[0]; ++i) {
        const size_t v = g.at(i, j, k);
        if (done[v]) continue;
        const bool negative = inside(i, j, k);
        done[v] = 1;
        if (negative) distance[v] = -distance[v];
        if (distance[v] <= band && distance[v] >= -band) continue;
        queue.assign(1, v);
        while (!queue.empty()) {
          const size_t u = queue.back();
          queue.pop_back();
          const int32_t ui = static_cast<int32_t>(u % g.n[0]);
          const int32_t uj = static_cast<int32_t>((u / g.n[0]) % g.n[1]);
          const int32_t uk = static_cast<int32_t>(u / (static_cast<size_t>(g.n[0]) * g.n[1]));
          const int32_t next[6][3] = {{ui - 1, uj, uk}, {ui + 1, uj, uk}, {ui, uj - 1, uk},
                                      {ui, uj + 1, uk}, {ui, uj, uk - 1}, {ui, uj, uk + 1}};
          for (const auto& c : next) {
            if (c[0] < 0 || c[0] >= g.n[0] || c[1] < 0 || c[1] >= g.n[1] || c[2] < 0 || c[2] >= g.n[2])
              continue;
            const size_t w = g.at(c[0], c[1], c[2]);
            if (done[w] || distance[w] <= band) continue;
            done[w] = 1;
            if (negative) distance[w] = -distance[w];
            queue.push_back(w);
          }
        }
      }
}

}  // namespace

std::shared_ptr<SdfAsset> build_mesh_sdf(const MeshSpec& s, uint64_t max_voxels) {
  require_argument(std::isfinite(s.voxel_size) && s.voxel_size > 0.0f,
                   "desc->voxel_size: must be finite and > 0");
  require_argument(std::isfinite(s.band_width) && s.band_width >= 1.0f && s.band_width <= 64.0f,
                   "desc->band_width: must be in [1, 64] voxels");
  require_argument(s.padding_voxels >= 1 && s.padding_voxels <= 1024,
                   "desc->padding_voxels: must be in [1, 1024]");
  V3 low, high;
  const HostVector<MeshTriangle> triangles = read_triangles(s, &low, &high);
  Grid g;
  g.voxel = s.voxel_size;
  double dims[3];
  // A mesh a whole number of voxels across gets that many (float rounding of its corners
  // must not add a voxel); the padding covers what the tolerance leaves out.
  for (int a = 0; a < 3; ++a)
    dims[a] = std::max(0.0, std::ceil((high[a] - low[a]) / g.voxel - 1e-4)) + 2.0 * s.padding_voxels + 1.0;
  const double total = dims[0] * dims[1] * dims[2];
  if (!(total <= static_cast<double>(max_voxels)))
    throw Error(Status::Capacity, "desc->voxel_size: the mesh's grid would have " + std::to_string(total) +
                                      " voxels, more than the limit of " + std::to_string(max_voxels));
  for (int a = 0; a < 3; ++a) g.n[a] = static_cast<int32_t>(dims[a]);
  // The grid as the asset stores it (floats), so distances are exact at its voxel centres.
  g.voxel = static_cast<float>(g.voxel);
  g.origin = (low - V3::Constant(s.padding_voxels * g.voxel)).cast<float>().cast<double>();
  // The grid's corners, its distances (up to its diagonal) and the difference of two of them
  // (trilinear sampling) must be finite in float: vertices near float's limits and far apart
  // (a grid about 1e38 m across) gave infinite distances and NaN samples.
  double diagonal2 = 0.0;
  bool corners_finite = true;
  for (int a = 0; a < 3; ++a) {
    const double side = (g.n[a] - 1) * g.voxel;
    diagonal2 += side * side;
    corners_finite = corners_finite && std::isfinite(static_cast<float>(g.origin[a])) &&
                     std::isfinite(static_cast<float>(g.origin[a] + side));
  }
  const double diagonal = std::sqrt(diagonal2);
  if (!corners_finite || !(diagonal <= 0.5 * std::numeric_limits<float>::max())) {
    char across[32];
    std::snprintf(across, sizeof across, "%.3g", diagonal);
    throw Error(Status::InvalidArgument,
                std::string("desc->vertices: the mesh's grid (its bounds plus padding) is ") + across +
                    " m across or reaches past float's range (+-3.4e38 m); "
                    "float distances need it within that and under 1.7e38 m across");
  }
  Affine3x4 index_to_local{};
  for (int a = 0; a < 3; ++a) {
    index_to_local.m[a * 4 + a] = static_cast<float>(g.voxel);
    index_to_local.m[a * 4 + 3] = static_cast<float>(g.origin[a]);
  }
  auto asset = make_sdf_asset(g.n[0], g.n[1], g.n[2], index_to_local);
  HostVector<float>& distance = asset->distance();
  distance.assign(asset->voxel_count(), INFINITY);
  HostVector<int32_t> closest(asset->voxel_count(), -1);
  const double band = s.band_width * g.voxel;
  fill_band(g, triangles, band, distance, closest);
  sweep_far_field(g, triangles, band, distance, closest);
  closest = HostVector<int32_t>();
  apply_sign(g, triangles, band, distance);
  return asset;
}

}  // namespace sph
