// SPDX-License-Identifier: MIT
// Colliders, sources, sinks and force fields inside a world, and the events of a step. The
// calls here convert public defs to specs (scene_specs.h) and hand them to the world's entry
// points, which validate them and name the field; "def->" goes in front of that name.
#include "../core/field_error.h"
#include "../core/pose_rules.h"
#include "coarse_sdf_warning.h"
#include "grid_from_public.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "public_vec3.h"
#include "struct_io.h"
#include "validate.h"

using sph::HostVector;

using sph::Error;
using sph::Status;
using sph::vec3_from_public;

namespace {

// A public transform as a pose (pose_rules.h: the all-zero quaternion is the identity, any
// other is normalised); errors name `field` + ".position" / ".rotation".
sph::RigidTransform pose_from_public(const sph_transform& t, const std::string& field) {
  return sph::pose_from_caller(sph::Vec3{t.position.x, t.position.y, t.position.z},
                               sph::Quat{t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w}, field);
}

sph_transform to_public(const sph::RigidTransform& t) {
  return sph_transform{sph_vec3{t.position.x, t.position.y, t.position.z},
                       sph_quat{t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w}};
}

// An SDF handle of the world's context, or NULL (whether one is required is the world's rule).
// The asset is taken under the handle registry's lock (use_sdf), so a racing sph_sdf_destroy
// cannot free it meanwhile.
std::shared_ptr<const sph::SdfAsset> world_sdf_or_null(const sph_world* world, const sph_sdf* sdf,
                                                       const std::string& name) {
  if (!sdf) return nullptr;
  sph::SdfUse use = sph::use_sdf(sdf, name);
  if (use.context.get() != world->context)
    throw Error(Status::InvalidArgument, name + ": belongs to another context than the world");
  return use.asset;
}

sph::ColliderMaterial material_from_public(const sph_collider_material& m) {
  sph::ColliderMaterial out;
  out.restitution = m.restitution;
  out.friction = m.friction;
  out.stickiness = m.stickiness;
  return out;
}

// The acceleration grid of a GRID force field: a velocity-only asset (components 0 = 3).
std::shared_ptr<const sph::SdfAsset> acceleration_grid(const sph_grid_desc* desc) {
  if (!desc) return nullptr;
  const sph_grid_desc g = sph::read_user_struct(desc, "def->grid");
  if (sph::grid_components(g, 3) != 3)
    throw Error(Status::InvalidArgument, "def->grid->components: must be 3 (or 0, meaning 3)");
  if (sph::enum_bits(g.memory) != SPH_MEMORY_HOST)
    throw Error(Status::Unsupported, "def->grid->memory: must be SPH_MEMORY_HOST");
  if (g.dims[0] == 0 || g.dims[1] == 0 || g.dims[2] == 0)
    throw Error(Status::InvalidArgument, "def->grid->dims: every dimension must be >= 1 (required)");
  if (!g.data) throw Error(Status::InvalidArgument, "def->grid->data: is NULL (required)");
  const uint64_t n = static_cast<uint64_t>(g.dims[0]) * g.dims[1] * g.dims[2];
  if (n > (1ull << 28)) throw Error(Status::Capacity, "def->grid->dims: more than 2^28 voxels");
  for (uint64_t i = 0; i < 3 * n; ++i)
    if (!std::isfinite(g.data[i]))
      throw Error(Status::InvalidArgument, "def->grid->data[" + std::to_string(i) + "]: is not finite");
  auto grid = sph::make_grid_asset(g, "def->grid->");
  grid->velocity().resize(n);
  std::memcpy(grid->velocity().data(), g.data, 3 * n * sizeof(float));
  return grid;
}

template <class Out>
sph_result copy_list(const Out* items, size_t n, Out* out, uint32_t capacity, uint32_t* out_count,
                     const char* name) {
  if (!out_count) throw Error(Status::InvalidArgument, "out_count: is NULL");
  if (capacity > 0 && !out)
    throw Error(Status::InvalidArgument, std::string(name) + ": is NULL but capacity > 0");
  const size_t written = std::min<size_t>(n, capacity);
  if (written > 0) std::memcpy(out, items, written * sizeof(Out));
  *out_count = static_cast<uint32_t>(n);
  return written < n ? SPH_INCOMPLETE : SPH_OK;
}

// The body of every call that changes one object of a world: lock, then `change(world)`.
template <class Change>
sph_result change_world(const char* function, sph_world* world, Change&& change) {
  return sph::guarded(function, sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    change(*world->world);
    return SPH_OK;
  });
}

}  // namespace

extern "C" {

SPH_API sph_transform SPH_CALL sph_transform_identity(void) { return to_public(sph::identity_pose()); }

/* ---- colliders ---- */

SPH_API sph_result SPH_CALL sph_collider_def_init_sized(sph_collider_def* def, uint32_t size) {
  return sph::init_user_struct("sph_collider_def_init", "def", def, size,
                               [](sph_collider_def& d) { d.transform = to_public(sph::identity_pose()); });
}

SPH_API sph_result SPH_CALL sph_collider_create(sph_world* world, const sph_collider_def* def,
                                                sph_collider_id* out_id) {
  return sph::guarded("sph_collider_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_collider_def d = sph::read_user_struct(def, "def");
    if (d.flags & ~SPH_COLLIDER_FLAG_INVERTED) throw Error(Status::Unsupported, "def->flags: unknown bits");
    sph::require_zero(d.reserved0, "def->reserved0");
    sph::require_zero(d.reserved1, "def->reserved1");
    std::shared_ptr<const sph::SdfAsset> sdf;
    out_id->bits = sph::with_field_prefix("def->", [&] {
      sph::ColliderSpec spec;
      spec.sdf = world_sdf_or_null(world, d.sdf, "def->sdf");
      sdf = spec.sdf;
      spec.pose = pose_from_public(d.transform, "transform");
      spec.material.restitution = d.restitution;
      spec.material.friction = d.friction;
      spec.material.stickiness = d.stickiness;
      spec.inverted = (d.flags & SPH_COLLIDER_FLAG_INVERTED) != 0;
      return world->world->add_collider(spec);
    });
    sph::warn_if_coarse_for_boundary_density(world, sdf.get());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_destroy(sph_world* world, sph_collider_id id) {
  return change_world("sph_collider_destroy", world, [&](sph::World& w) { w.remove_collider(id.bits); });
}

SPH_API sph_result SPH_CALL sph_collider_set_target_transform(sph_world* world, sph_collider_id id,
                                                              const sph_transform* target) {
  return change_world("sph_collider_set_target_transform", world, [&](sph::World& w) {
    if (!target) throw Error(Status::InvalidArgument, "target: is NULL");
    w.set_collider_target(id.bits, pose_from_public(*target, "target"));
  });
}

SPH_API sph_result SPH_CALL sph_collider_teleport(sph_world* world, sph_collider_id id,
                                                  const sph_transform* transform) {
  return change_world("sph_collider_teleport", world, [&](sph::World& w) {
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    w.teleport_collider(id.bits, pose_from_public(*transform, "transform"));
  });
}

SPH_API sph_result SPH_CALL sph_collider_get_transform(const sph_world* world, sph_collider_id id,
                                                       sph_transform* out_transform) {
  return sph::guarded("sph_collider_get_transform", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_transform) throw Error(Status::InvalidArgument, "out_transform: is NULL");
    *out_transform = to_public(world->world->collider(id.bits).pose);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_material_init_sized(sph_collider_material* material, uint32_t size) {
  return sph::init_user_struct("sph_collider_material_init", "material", material, size);
}

SPH_API sph_result SPH_CALL sph_collider_set_material(sph_world* world, sph_collider_id id,
                                                      const sph_collider_material* material) {
  return change_world("sph_collider_set_material", world, [&](sph::World& w) {
    const sph_collider_material m = sph::read_user_struct(material, "material");
    sph::with_field_prefix("material->", [&] { w.set_collider_material(id.bits, material_from_public(m)); });
  });
}

SPH_API sph_result SPH_CALL sph_collider_get_material(const sph_world* world, sph_collider_id id,
                                                      sph_collider_material* out) {
  return sph::guarded("sph_collider_get_material", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::ColliderMaterial& m = world->world->collider(id.bits).material;
    sph_collider_material o = sph::zeroed_struct<sph_collider_material>();
    o.restitution = m.restitution;
    o.friction = m.friction;
    o.stickiness = m.stickiness;
    sph::write_output_struct(out, o, "out");
    return SPH_OK;
  });
}

/* ---- sources ---- */

SPH_API sph_result SPH_CALL sph_source_def_init_sized(sph_source_def* def, uint32_t size) {
  return sph::init_user_struct("sph_source_def_init", "def", def, size, [](sph_source_def& d) {
    d.mode = SPH_SOURCE_FILL_ONCE;
    d.transform = to_public(sph::identity_pose());
  });
}

SPH_API sph_result SPH_CALL sph_source_create(sph_world* world, const sph_source_def* def,
                                              sph_source_id* out_id) {
  return sph::guarded("sph_source_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_source_def d = sph::read_user_struct(def, "def");
    const uint32_t mode = sph::enum_bits(d.mode);
    if (mode != SPH_SOURCE_FILL_ONCE && mode != SPH_SOURCE_CONTINUOUS)
      throw Error(Status::Unsupported, "def->mode: " + std::to_string(static_cast<int32_t>(mode)) +
                                           " is not an sph_source_mode value");
    if (d.flags & ~SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD)
      throw Error(Status::Unsupported, "def->flags: unknown bits");
    sph::require_zero(d.reserved1, "def->reserved1");
    out_id->bits = sph::with_field_prefix("def->", [&] {
      sph::SourceSpec spec;
      spec.user_attribute = d.user_attribute;
      spec.region = world_sdf_or_null(world, d.region, "def->region");
      spec.pose = pose_from_public(d.transform, "transform");
      spec.mode = static_cast<sph::SourceMode>(mode);
      spec.spacing = d.spacing;
      spec.min_distance = d.min_distance;
      spec.velocity = vec3_from_public(d.velocity);
      spec.velocity_from_field = (d.flags & SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD) != 0;
      spec.rate = d.rate;
      return world->world->add_source(spec);
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_source_destroy(sph_world* world, sph_source_id id) {
  return change_world("sph_source_destroy", world, [&](sph::World& w) { w.remove_source(id.bits); });
}

SPH_API sph_result SPH_CALL sph_source_set_transform(sph_world* world, sph_source_id id,
                                                     const sph_transform* transform) {
  return change_world("sph_source_set_transform", world, [&](sph::World& w) {
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    w.set_source_pose(id.bits, pose_from_public(*transform, "transform"));
  });
}

/* ---- sinks ---- */

SPH_API sph_result SPH_CALL sph_sink_def_init_sized(sph_sink_def* def, uint32_t size) {
  return sph::init_user_struct("sph_sink_def_init", "def", def, size, [](sph_sink_def& d) {
    d.mode = SPH_SINK_REGION;
    d.transform = to_public(sph::identity_pose());
  });
}

SPH_API sph_result SPH_CALL sph_sink_create(sph_world* world, const sph_sink_def* def, sph_sink_id* out_id) {
  return sph::guarded("sph_sink_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_sink_def d = sph::read_user_struct(def, "def");
    sph::require_zero(d.reserved0, "def->reserved0");
    const uint32_t mode = sph::enum_bits(d.mode);
    if (mode != SPH_SINK_REGION && mode != SPH_SINK_OUTSIDE_BOUNDS)
      throw Error(Status::Unsupported, "def->mode: " + std::to_string(static_cast<int32_t>(mode)) +
                                           " is not an sph_sink_mode value");
    out_id->bits = sph::with_field_prefix("def->", [&] {
      sph::SinkSpec spec;
      // Each mode reads only its own fields (the others are ignored, as documented).
      if (mode == SPH_SINK_REGION) {
        spec.mode = sph::SinkMode::Region;
        spec.region = world_sdf_or_null(world, d.region, "def->region");
        spec.pose = pose_from_public(d.transform, "transform");
      } else {
        spec.mode = sph::SinkMode::OutsideBounds;
        spec.bounds_min = vec3_from_public(d.bounds_min);
        spec.bounds_max = vec3_from_public(d.bounds_max);
      }
      return world->world->add_sink(spec);
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sink_destroy(sph_world* world, sph_sink_id id) {
  return change_world("sph_sink_destroy", world, [&](sph::World& w) { w.remove_sink(id.bits); });
}

/* ---- force fields ---- */

SPH_API sph_result SPH_CALL sph_force_field_def_init_sized(sph_force_field_def* def, uint32_t size) {
  return sph::init_user_struct("sph_force_field_def_init", "def", def, size, [](sph_force_field_def& d) {
    d.kind = SPH_FORCE_FIELD_UNIFORM;
    d.transform = to_public(sph::identity_pose());
  });
}

SPH_API sph_result SPH_CALL sph_force_field_create(sph_world* world, const sph_force_field_def* def,
                                                   sph_force_field_id* out_id) {
  return sph::guarded("sph_force_field_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_force_field_def d = sph::read_user_struct(def, "def");
    const uint32_t kind = sph::enum_bits(d.kind);
    if (kind > SPH_FORCE_FIELD_GRID)
      throw Error(Status::Unsupported, "def->kind: " + std::to_string(static_cast<int32_t>(kind)) +
                                           " is not an sph_force_field_kind value");
    sph::require_zero(d.reserved0, "def->reserved0");
    sph::require_zero(d.reserved1, "def->reserved1");
    out_id->bits = sph::with_field_prefix("def->", [&] {
      sph::ForceFieldSpec spec;
      spec.kind = static_cast<sph::ForceFieldKind>(kind);
      spec.pose = pose_from_public(d.transform, "transform");
      spec.region = world_sdf_or_null(world, d.region, "def->region");
      spec.vector = vec3_from_public(d.vector);
      // The public def takes any non-zero axis; the world keeps it normalised.
      if (spec.kind == sph::ForceFieldKind::Vortex)
        spec.vector = sph::unit_axis_from_caller(spec.vector, "vector", "a vortex");
      spec.strength = d.strength;
      spec.falloff_radius = d.falloff_radius;
      // Only a GRID field reads def->grid (the other kinds ignore it, as documented).
      if (spec.kind == sph::ForceFieldKind::Grid) spec.grid = acceleration_grid(d.grid);
      return world->world->add_force_field(spec);
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_force_field_destroy(sph_world* world, sph_force_field_id id) {
  return change_world("sph_force_field_destroy", world,
                      [&](sph::World& w) { w.remove_force_field(id.bits); });
}

SPH_API sph_result SPH_CALL sph_force_field_set_transform(sph_world* world, sph_force_field_id id,
                                                          const sph_transform* transform) {
  return change_world("sph_force_field_set_transform", world, [&](sph::World& w) {
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    w.set_force_field_pose(id.bits, pose_from_public(*transform, "transform"));
  });
}

/* ---- events ---- */

SPH_API sph_result SPH_CALL sph_world_get_events(const sph_world* world, sph_event* events, uint32_t capacity,
                                                 uint32_t* out_count) {
  return sph::guarded("sph_world_get_events", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    HostVector<sph_event> list;
    for (const sph::Event& e : world->world->events()) {
      sph_event out;
      out.type = static_cast<sph_event_type>(e.type);
      out.count = e.count;
      out.object_bits = e.object_id;
      list.push_back(out);
    }
    return copy_list(list.data(), list.size(), events, capacity, out_count, "events");
  });
}

SPH_API sph_result SPH_CALL sph_world_get_removed_ids(const sph_world* world, uint32_t* ids,
                                                      uint32_t capacity, uint32_t* out_count) {
  return sph::guarded("sph_world_get_removed_ids", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const auto& removed = world->world->removed_ids();
    return copy_list(removed.data(), removed.size(), ids, capacity, out_count, "ids");
  });
}

}  // extern "C"
