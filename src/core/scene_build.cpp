// SPDX-License-Identifier: MIT
#include "scene_build.h"

#include <algorithm>

#include "field_checks.h"
#include "pose_rules.h"

namespace sph {
namespace {

void require_asset(const std::shared_ptr<const SdfAsset>& asset, const char* field, const char* why) {
  if (!asset) throw FieldError(Status::InvalidArgument, field, std::string("is NULL; ") + why);
}

}  // namespace

void check_collider_material(const ColliderMaterial& m) {
  require_finite_field(m.restitution, "restitution");
  if (m.restitution < 0.0f || m.restitution > 1.0f)
    throw FieldError(Status::InvalidArgument, "restitution",
                     "must be in [0, 1], got " + describe_value(m.restitution));
  require_non_negative_field(m.friction, "friction");
  require_non_negative_field(m.stickiness, "stickiness");
}

Collider make_collider(const ColliderSpec& spec) {
  require_asset(spec.sdf, "sdf", "a collider needs an SDF asset (required)");
  require_pose(spec.pose, "transform");
  check_collider_material(spec.material);
  Collider c;
  c.sdf = spec.sdf;
  c.pose = spec.pose;
  c.material = spec.material;
  c.inverted = spec.inverted;
  return c;
}

Source make_source(const SourceSpec& spec, const WorldConfig& config) {
  if (spec.mode != SourceMode::FillOnce && spec.mode != SourceMode::Continuous)
    throw FieldError(Status::Unsupported, "mode",
                     std::to_string(static_cast<uint32_t>(spec.mode)) + " is not a source mode");
  require_particle_velocity_field(spec.velocity, "velocity");
  require_non_negative_field(spec.spacing, "spacing");
  require_non_negative_field(spec.min_distance, "min_distance");
  require_non_negative_field(spec.rate, "rate");
  require_asset(spec.region, "region", "a source needs a region to fill (required)");
  if (spec.velocity_from_field && !spec.region->has_velocity())
    throw FieldError(Status::InvalidArgument, "flags",
                     "VELOCITY_FROM_FIELD but the region has no velocity channel");
  require_pose(spec.pose, "transform");
  Source s;
  s.region = spec.region;
  s.pose = spec.pose;
  s.mode = spec.mode;
  s.spacing = spec.spacing == 0.0f ? config.particle_spacing : spec.spacing;
  if (s.spacing < 0.25f * config.particle_spacing)
    throw FieldError(Status::InvalidArgument, "spacing",
                     describe_value(s.spacing) + " is below a quarter of the world's particle spacing");
  // The default keeps within the kernel radius (the emission's neighbour search reaches no
  // farther), so that a default is never refused for a field the caller did not set.
  s.min_distance =
      spec.min_distance == 0.0f ? std::min(0.9f * s.spacing, config.kernel_radius) : spec.min_distance;
  if (s.min_distance > config.kernel_radius)
    throw FieldError(Status::InvalidArgument, "min_distance",
                     describe_value(s.min_distance) + " is larger than the kernel radius " +
                         describe_value(config.kernel_radius));
  if (s.min_distance > s.spacing)
    throw FieldError(Status::InvalidArgument, "min_distance", "must not exceed the source's spacing");
  s.velocity = spec.velocity;
  s.velocity_from_field = spec.velocity_from_field;
  s.rate = spec.rate;
  if (spec.user_attribute != 0 && !(config.features & kFeatureUserAttribute))
    throw FieldError(Status::FeatureDisabled, "user_attribute",
                     "is not 0 but SPH_FEATURE_USER_ATTRIBUTE is not enabled in the world's def");
  s.user_attribute = spec.user_attribute;
  return s;
}

Sink make_sink(const SinkSpec& spec) {
  if (spec.mode == SinkMode::Region) {
    require_asset(spec.region, "region", "a REGION sink needs a region (required)");
  } else if (spec.mode == SinkMode::OutsideBounds) {
    if (spec.region) throw FieldError(Status::InvalidArgument, "region", "an OUTSIDE_BOUNDS sink has none");
  } else {
    throw FieldError(Status::Unsupported, "mode",
                     std::to_string(static_cast<uint32_t>(spec.mode)) + " is not a sink mode");
  }
  require_pose(spec.pose, "transform");
  require_finite_vec3_field(spec.bounds_min, "bounds_min");
  require_finite_vec3_field(spec.bounds_max, "bounds_max");
  if (!(spec.bounds_max.x >= spec.bounds_min.x && spec.bounds_max.y >= spec.bounds_min.y &&
        spec.bounds_max.z >= spec.bounds_min.z))
    throw FieldError(Status::InvalidArgument, "bounds_max", "every component must be >= bounds_min's");
  Sink s;
  s.mode = spec.mode;
  s.region = spec.region;
  s.pose = spec.pose;
  s.bounds_min = spec.bounds_min;
  s.bounds_max = spec.bounds_max;
  return s;
}

ForceField make_force_field(const ForceFieldSpec& spec) {
  if (static_cast<uint32_t>(spec.kind) > static_cast<uint32_t>(ForceFieldKind::Grid))
    throw FieldError(Status::Unsupported, "kind",
                     std::to_string(static_cast<uint32_t>(spec.kind)) + " is not a force field kind");
  require_finite_vec3_field(spec.vector, "vector");
  require_finite_field(spec.strength, "strength");
  require_non_negative_field(spec.falloff_radius, "falloff_radius");
  require_pose(spec.pose, "transform");
  if (spec.kind == ForceFieldKind::Vortex) require_unit_axis(spec.vector, "vector", "a vortex");
  if (spec.kind == ForceFieldKind::Grid) {
    require_asset(spec.grid, "grid", "a GRID field needs its acceleration grid (required)");
    if (!spec.grid->has_velocity())
      throw FieldError(Status::InvalidArgument, "grid", "has no acceleration channel");
  } else if (spec.grid) {
    throw FieldError(Status::InvalidArgument, "grid", "only a GRID field has one");
  }
  ForceField f;
  f.kind = spec.kind;
  f.region = spec.region;
  f.grid = spec.grid;
  f.pose = spec.pose;
  f.vector = spec.vector;
  f.strength = spec.strength;
  f.falloff_radius = spec.falloff_radius;
  return f;
}

}  // namespace sph
