// SPDX-License-Identifier: MIT
#include "sdf_shapes.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

#include "status.h"

namespace sph {
namespace {

using V3 = Eigen::Vector3d;

double box_distance(const V3& p, const V3& half) {
  const V3 q = p.cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

double cylinder_distance(const V3& p, double radius, double half_height) {
  const Eigen::Vector2d d(std::hypot(p.x(), p.z()) - radius, std::fabs(p.y()) - half_height);
  return d.cwiseMax(0.0).norm() + std::min(std::max(d.x(), d.y()), 0.0);
}

// Bounds of the solid, for sizing the grid.
V3 shape_half_bounds(const ShapeSpec& s) {
  const double w = s.wall_thickness;
  switch (s.kind) {
    case ShapeKind::Plane:
      return V3(s.half_extents.x, s.half_extents.y, s.half_extents.z);
    case ShapeKind::Box:
      return V3(s.half_extents.x + w, s.half_extents.y + w, s.half_extents.z + w);
    case ShapeKind::Sphere:
      return V3(s.radius, s.radius, s.radius);
    case ShapeKind::Capsule:
      return V3(s.radius, s.half_height + s.radius, s.radius);
    case ShapeKind::Cylinder:
      return V3(s.radius, s.half_height, s.radius);
    case ShapeKind::Cup:
      return V3(s.radius + w, s.half_height, s.radius + w);
  }
  return V3::Zero();
}

}  // namespace

float shape_distance(const ShapeSpec& s, Vec3 point) {
  const V3 p(point.x, point.y, point.z);
  const double w = s.wall_thickness;
  switch (s.kind) {
    case ShapeKind::Plane:
      // The solid is everything below y = 0 (within the grid; the grid's extent bounds it).
      return static_cast<float>(p.y());
    case ShapeKind::Box: {
      const V3 half(s.half_extents.x, s.half_extents.y, s.half_extents.z);
      if (w <= 0.0) return static_cast<float>(box_distance(p, half));
      // A tank: the walls between the outer box and the interior; an open top extends the
      // cavity up through the lid.
      const double outer = box_distance(p, half + V3::Constant(w));
      double inner;
      if (s.open_top) {
        const V3 cavity_half(half.x(), half.y() + w, half.z());
        inner = box_distance(p - V3(0.0, w, 0.0), cavity_half);
      } else {
        inner = box_distance(p, half);
      }
      return static_cast<float>(std::max(outer, -inner));
    }
    case ShapeKind::Sphere:
      return static_cast<float>(p.norm() - s.radius);
    case ShapeKind::Capsule: {
      const double y =
          std::clamp(p.y(), -static_cast<double>(s.half_height), static_cast<double>(s.half_height));
      return static_cast<float>((p - V3(0.0, y, 0.0)).norm() - s.radius);
    }
    case ShapeKind::Cylinder:
      return static_cast<float>(cylinder_distance(p, s.radius, s.half_height));
    case ShapeKind::Cup: {
      // Outer cylinder minus a cavity of the inner radius from the floor (thickness w) up
      // through the rim.
      const double outer = cylinder_distance(p, s.radius + w, s.half_height);
      const double cavity_half = s.half_height;  // from -half_height + w to half_height + w
      const double inner = cylinder_distance(p - V3(0.0, w, 0.0), s.radius, cavity_half);
      return static_cast<float>(std::max(outer, -inner));
    }
  }
  return 0.0f;
}

std::shared_ptr<SdfAsset> build_shape_sdf(const ShapeSpec& s, uint64_t max_voxels) {
  require_argument(std::isfinite(s.voxel_size) && s.voxel_size > 0.0f,
                   "desc->voxel_size: must be finite and > 0");
  require_argument(s.padding_voxels >= 1 && s.padding_voxels <= 1024,
                   "desc->padding_voxels: must be in [1, 1024]");
  const V3 half = shape_half_bounds(s);
  require_argument(half.allFinite() && (half.array() > 0.0).all(),
                   "desc: the shape's dimensions must be finite and > 0 (half_extents, radius, half_height)");
  require_argument(std::isfinite(s.wall_thickness) && s.wall_thickness >= 0.0f,
                   "desc->wall_thickness: must be >= 0");
  if (s.kind == ShapeKind::Cup)
    require_argument(s.wall_thickness > 0.0f, "desc->wall_thickness: a cup needs walls > 0");
  const double voxel = s.voxel_size;
  double dims[3];
  for (int a = 0; a < 3; ++a) dims[a] = 2.0 * std::ceil(half[a] / voxel) + 2.0 * s.padding_voxels + 1.0;
  const double total = dims[0] * dims[1] * dims[2];
  if (!(total <= static_cast<double>(max_voxels)))
    throw Error(Status::Capacity, "desc->voxel_size: the grid would have " + std::to_string(total) +
                                      " voxels, more than the limit of " + std::to_string(max_voxels));
  const int32_t n[3] = {static_cast<int32_t>(dims[0]), static_cast<int32_t>(dims[1]),
                        static_cast<int32_t>(dims[2])};
  // Voxel centres at integer indices, the grid centred on the shape's origin.
  Affine3x4 index_to_local{};
  for (int a = 0; a < 3; ++a) {
    index_to_local.m[a * 4 + a] = static_cast<float>(voxel);
    index_to_local.m[a * 4 + 3] = static_cast<float>(-0.5 * (n[a] - 1) * voxel);
  }
  auto asset = make_sdf_asset(n[0], n[1], n[2], index_to_local);
  HostVector<float>& d = asset->distance();
  for (int32_t k = 0; k < n[2]; ++k)
    for (int32_t j = 0; j < n[1]; ++j)
      for (int32_t i = 0; i < n[0]; ++i) {
        const Vec3 local = apply_affine(
            index_to_local, Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)});
        d[static_cast<size_t>(i) + static_cast<size_t>(n[0]) * (j + static_cast<size_t>(n[1]) * k)] =
            shape_distance(s, local);
      }
  return asset;
}

}  // namespace sph
