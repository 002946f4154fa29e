// SPDX-License-Identifier: MIT
// What a world's entry points take to make its scene objects and fills: plain values, as the C
// layer converts them from the public defs and the checkpoint reader reads them from a file.
// The entry points (World::add_collider and the like) validate every field through
// scene_build.h and name it in their errors as the public def names it ("restitution",
// "transform.rotation"); nothing here is trusted.
#pragma once

#include <memory>

#include "../physics/force_fields.h"
#include "../physics/rigid_transform.h"
#include "../physics/sink_region.h"
#include "sdf_asset.h"

namespace sph {

// The identity pose: what a def's all-zero transform means.
inline RigidTransform identity_pose() { return RigidTransform{{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}}; }

struct ColliderMaterial {
  float restitution = 0.0f;  // share of the normal approach speed returned, [0, 1]
  float friction = 0.0f;     // Coulomb coefficient, >= 0
  float stickiness = 0.0f;   // pull toward the surface within one kernel radius, m/s^2, >= 0
};

struct ColliderSpec {
  std::shared_ptr<const SdfAsset> sdf;    // required
  RigidTransform pose = identity_pose();  // a finite position and a unit rotation
  ColliderMaterial material;
  bool inverted = false;  // solid where the SDF is positive
};

enum class SourceMode : uint32_t { FillOnce = 0, Continuous = 1 };

struct SourceSpec {
  std::shared_ptr<const SdfAsset> region;  // required
  RigidTransform pose = identity_pose();
  SourceMode mode = SourceMode::FillOnce;
  float spacing = 0.0f;       // FCC spacing; 0 = the world's particle spacing
  float min_distance = 0.0f;  // 0 = 0.9 x spacing; at most the kernel radius and the spacing
  Vec3 velocity{0.0f, 0.0f, 0.0f};
  bool velocity_from_field = false;  // the region's velocity channel instead of `velocity`
  float rate = 0.0f;                 // Continuous: particles per second at most; 0 = no limit
  uint32_t user_attribute = 0;       // its particles'; non-zero needs kFeatureUserAttribute
};

struct SinkSpec {
  SinkMode mode = SinkMode::Region;
  std::shared_ptr<const SdfAsset> region;  // Region: required; OutsideBounds: none
  RigidTransform pose = identity_pose();
  Vec3 bounds_min{0.0f, 0.0f, 0.0f};  // OutsideBounds: the box particles may stay in
  Vec3 bounds_max{0.0f, 0.0f, 0.0f};
};

// A probe or gauge (sph_probe_def; world_probes.cpp checks it).
struct ProbeSpec {
  bool gauge = false;
  bool every_substep = false;
  Vec3 position{0.0f, 0.0f, 0.0f};
  Vec3 direction{0.0f, 0.0f, 0.0f};  // gauges; zero: against gravity
  float length = 0.0f;               // gauges: > 0
  float sample_spacing = 0.0f;       // gauges: >= 0; 0 = kernel radius / 8
};

struct ForceFieldSpec {
  ForceFieldKind kind = ForceFieldKind::Uniform;
  std::shared_ptr<const SdfAsset> region;  // optional: acts only where it is negative
  std::shared_ptr<const SdfAsset> grid;    // Grid: required, with accelerations in its velocity channel
  RigidTransform pose = identity_pose();
  Vec3 vector{0.0f, 0.0f, 0.0f};  // Uniform: the acceleration; Vortex: the unit axis
  float strength = 0.0f;          // Radial, Vortex: m/s^2
  float falloff_radius = 0.0f;    // Radial, Vortex: 0 = no fade
};

struct FillBoxSpec {
  Vec3 min{0.0f, 0.0f, 0.0f};
  Vec3 max{0.0f, 0.0f, 0.0f};  // every component >= min's; an empty box fills nothing
  Vec3 velocity{0.0f, 0.0f, 0.0f};
};

struct FillSphereSpec {
  Vec3 center{0.0f, 0.0f, 0.0f};
  float radius = 0.0f;  // >= 0; 0 fills nothing
  Vec3 velocity{0.0f, 0.0f, 0.0f};
};

}  // namespace sph
