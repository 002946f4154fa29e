// SPDX-License-Identifier: MIT
// External force fields inside a region (thesis 4.4.2.4): uniform, radial, vortex and a grid
// of accelerations. Each yields an acceleration in m/s^2.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "rigid_transform.h"
#include "sdf_sampling.h"
#include "vec3.h"

namespace sph {

enum class ForceFieldKind : uint32_t { Uniform = 0, Radial = 1, Vortex = 2, Grid = 3 };

struct ForceFieldView {
  ForceFieldKind kind;
  uint32_t has_region;   // 0: everywhere
  SdfGridView region;    // inside where negative
  RigidTransform pose;   // field frame
  Vec3 vector;           // uniform: acceleration (field frame); vortex: axis (field frame, unit)
  float strength;        // radial: m/s^2, > 0 pushes away from the centre; vortex: m/s^2
  float falloff_radius;  // radial/vortex: linear fade to zero at this distance; 0 = none
  SdfGridView grid;      // grid fields: accelerations (field frame) in grid.velocity
};

SPH_HD float falloff(float r, float radius) {
  if (radius <= 0.0f) return 1.0f;
  return r >= radius ? 0.0f : 1.0f - r / radius;
}

SPH_HD Vec3 force_field_acceleration(const ForceFieldView& f, Vec3 world) {
  const Vec3 local = to_local(f.pose, world);
  if (f.has_region && sample_distance(f.region, local) >= 0.0f) return Vec3{0.0f, 0.0f, 0.0f};
  Vec3 a{0.0f, 0.0f, 0.0f};
  switch (f.kind) {
    case ForceFieldKind::Uniform:
      a = f.vector;
      break;
    case ForceFieldKind::Radial: {
      const float r = length(local);
      if (r > 0.0f) a = local * (f.strength * falloff(r, f.falloff_radius) / r);
      break;
    }
    case ForceFieldKind::Vortex: {
      // Tangential around the axis through the field's origin.
      const Vec3 radial = local - f.vector * dot(local, f.vector);
      const float r = length(radial);
      if (r > 0.0f) a = cross(f.vector, radial) * (f.strength * falloff(r, f.falloff_radius) / r);
      break;
    }
    case ForceFieldKind::Grid:
      a = sample_velocity(f.grid, local);
      break;
  }
  return direction_to_world(f.pose, a);
}

}  // namespace sph
