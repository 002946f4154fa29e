// SPDX-License-Identifier: MIT
// Analytic shapes sampled into SDF assets: plane, box (solid or a hollow tank), sphere,
// capsule, cylinder and an open cup. Each shape is centred at its local origin with Y up.
#pragma once

#include <memory>

#include "../physics/vec3.h"
#include "sdf_asset.h"

namespace sph {

enum class ShapeKind : uint32_t { Plane = 0, Box = 1, Sphere = 2, Capsule = 3, Cylinder = 4, Cup = 5 };

struct ShapeSpec {
  ShapeKind kind = ShapeKind::Box;
  Vec3 half_extents{0.5f, 0.5f, 0.5f};  // box; plane uses x and z for its size, y for its thickness
  float radius = 0.5f;                  // sphere, capsule, cylinder, cup (inner radius)
  float half_height = 0.5f;             // capsule (segment), cylinder, cup
  float wall_thickness = 0.0f;          // hollow box and cup walls; 0 = solid box
  bool open_top = false;                // hollow box: no lid
  float voxel_size = 0.01f;
  int32_t padding_voxels = 4;  // grid margin around the shape's bounds
};

// The exact signed distance of the shape at a local point (negative inside the solid).
float shape_distance(const ShapeSpec& s, Vec3 p);

// Samples the shape on a grid of voxel_size covering its bounds plus padding. Throws
// Error(InvalidArgument) on bad dimensions and Error(Capacity) beyond max_voxels.
std::shared_ptr<SdfAsset> build_shape_sdf(const ShapeSpec& s, uint64_t max_voxels);

}  // namespace sph
