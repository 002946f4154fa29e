// Colliders, sources, sinks and force fields inside a world, and the events of a step.
#include "../core/scene_objects.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

constexpr size_t kMaxObjectsPerKind = 65536;
constexpr uint64_t kMaxSourceLatticePoints = 1ull << 28;

sph::RigidTransform read_transform(const sph_transform& t, const std::string& name) {
  sph::require_finite_vec3(t.position, (name + ".position").c_str());
  const sph_quat q = t.rotation;
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w))
    throw Error(Status::InvalidArgument, name + ".rotation: has a non-finite component");
  const float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(n > 1e-6f) || !std::isfinite(n))
    throw Error(Status::InvalidArgument, name + ".rotation: is not a rotation (zero length)");
  return sph::RigidTransform{sph::Vec3{t.position.x, t.position.y, t.position.z},
                             sph::Quat{q.x / n, q.y / n, q.z / n, q.w / n}};
}

sph_transform to_public(const sph::RigidTransform& t) {
  return sph_transform{sph_vec3{t.position.x, t.position.y, t.position.z},
                       sph_quat{t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w}};
}

// An SDF handle that belongs to the world's context; returns the asset.
std::shared_ptr<sph::SdfAsset> require_world_sdf(const sph_world* world, const sph_sdf* sdf,
                                                 const std::string& name) {
  if (!sdf) throw Error(Status::InvalidArgument, name + ": is NULL");
  if (!sph::is_live_handle(sdf, sph::HandleKind::Sdf))
    throw Error(Status::InvalidHandle, name + ": is not a live sph_sdf");
  if (sdf->context != world->context)
    throw Error(Status::InvalidArgument, name + ": belongs to another context than the world");
  return sdf->asset;
}

void require_room(size_t count, const char* kind) {
  if (count >= kMaxObjectsPerKind)
    throw Error(Status::Capacity, std::string("a world holds at most 65536 ") + kind);
}

void check_material(float restitution, float friction, float stickiness, const std::string& prefix) {
  sph::require_finite(restitution, (prefix + "restitution").c_str());
  if (restitution < 0.0f || restitution > 1.0f)
    throw Error(Status::InvalidArgument,
                prefix + "restitution: must be in [0, 1], got " + sph::describe(restitution));
  sph::require_non_negative(friction, (prefix + "friction").c_str());
  sph::require_non_negative(stickiness, (prefix + "stickiness").c_str());
}

template <class T>
T* find_object(sph::SlotMap<T>& map, uint64_t bits, const char* name) {
  T* object = map.find(bits);
  if (!object)
    throw Error(Status::InvalidHandle, std::string(name) + ": is null, stale or not of this world");
  return object;
}

template <class T>
sph_result destroy_object(sph_world* world, sph::SlotMap<T>& (sph::World::*map)(), uint64_t bits,
                          const char* name) {
  if (bits == 0) return SPH_OK;
  if (!(world->world.get()->*map)().erase(bits))
    throw Error(Status::InvalidHandle, std::string(name) + ": is stale or not of this world");
  return SPH_OK;
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

sph::RigidTransform identity() { return sph::RigidTransform{sph::Vec3{0, 0, 0}, sph::Quat{0, 0, 0, 1}}; }

}  // namespace

extern "C" {

SPH_API sph_transform SPH_CALL sph_transform_identity(void) { return to_public(identity()); }

/* ---- colliders ---- */

SPH_API sph_result SPH_CALL sph_collider_def_init_sized(sph_collider_def* def, uint32_t size) {
  return sph::init_user_struct("sph_collider_def_init", "def", def, size,
                               [](sph_collider_def& d) { d.transform = to_public(identity()); });
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
    check_material(d.restitution, d.friction, d.stickiness, "def->");
    sph::Collider c;
    c.sdf = require_world_sdf(world, d.sdf, "def->sdf");
    c.pose = read_transform(d.transform, "def->transform");
    c.restitution = d.restitution;
    c.friction = d.friction;
    c.stickiness = d.stickiness;
    c.inverted = (d.flags & SPH_COLLIDER_FLAG_INVERTED) != 0;
    require_room(world->world->colliders().size(), "colliders");
    out_id->bits = world->world->colliders().insert(std::move(c));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_destroy(sph_world* world, sph_collider_id id) {
  return sph::guarded("sph_collider_destroy", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    return destroy_object(world, &sph::World::colliders, id.bits, "id");
  });
}

SPH_API sph_result SPH_CALL sph_collider_set_target_transform(sph_world* world, sph_collider_id id,
                                                              const sph_transform* target) {
  return sph::guarded("sph_collider_set_target_transform", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!target) throw Error(Status::InvalidArgument, "target: is NULL");
    sph::Collider* c = find_object(world->world->colliders(), id.bits, "id");
    c->target = read_transform(*target, "target");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_teleport(sph_world* world, sph_collider_id id,
                                                  const sph_transform* transform) {
  return sph::guarded("sph_collider_teleport", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    sph::Collider* c = find_object(world->world->colliders(), id.bits, "id");
    c->pose = read_transform(*transform, "transform");
    c->target.reset();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_get_transform(const sph_world* world, sph_collider_id id,
                                                       sph_transform* out_transform) {
  return sph::guarded("sph_collider_get_transform", sph::context_of(world), [&] {
    sph::require_world(world);
    if (!out_transform) throw Error(Status::InvalidArgument, "out_transform: is NULL");
    const sph::Collider* c = const_cast<sph_world*>(world)->world->colliders().find(id.bits);
    if (!c) throw Error(Status::InvalidHandle, "id: is null, stale or not of this world");
    *out_transform = to_public(c->pose);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_set_material(sph_world* world, sph_collider_id id, float restitution,
                                                      float friction, float stickiness) {
  return sph::guarded("sph_collider_set_material", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    check_material(restitution, friction, stickiness, "");
    sph::Collider* c = find_object(world->world->colliders(), id.bits, "id");
    c->restitution = restitution;
    c->friction = friction;
    c->stickiness = stickiness;
    return SPH_OK;
  });
}

/* ---- sources ---- */

SPH_API sph_result SPH_CALL sph_source_def_init_sized(sph_source_def* def, uint32_t size) {
  return sph::init_user_struct("sph_source_def_init", "def", def, size, [](sph_source_def& d) {
    d.mode = SPH_SOURCE_FILL_ONCE;
    d.transform = to_public(identity());
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
    sph::require_zero(d.reserved0, "def->reserved0");
    sph::require_zero(d.reserved1, "def->reserved1");
    sph::require_finite_vec3(d.velocity, "def->velocity");
    sph::require_non_negative(d.spacing, "def->spacing");
    sph::require_non_negative(d.min_distance, "def->min_distance");
    sph::require_non_negative(d.rate, "def->rate");
    const sph::WorldConfig& cfg = world->world->config();
    sph::Source s;
    s.region = require_world_sdf(world, d.region, "def->region");
    if ((d.flags & SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD) && !s.region->has_velocity())
      throw Error(Status::InvalidArgument,
                  "def->flags: VELOCITY_FROM_FIELD but def->region has no velocity channel");
    s.pose = read_transform(d.transform, "def->transform");
    s.mode = static_cast<sph::SourceMode>(mode);
    s.spacing = d.spacing == 0.0f ? cfg.particle_spacing : d.spacing;
    if (s.spacing < 0.25f * cfg.particle_spacing)
      throw Error(Status::InvalidArgument, "def->spacing: " + sph::describe(s.spacing) +
                                               " is below a quarter of the world's particle spacing");
    s.min_distance = d.min_distance == 0.0f ? 0.9f * s.spacing : d.min_distance;
    if (s.min_distance > cfg.kernel_radius)
      throw Error(Status::InvalidArgument, "def->min_distance: " + sph::describe(s.min_distance) +
                                               " is larger than the kernel radius " +
                                               sph::describe(cfg.kernel_radius));
    if (s.min_distance > s.spacing)
      throw Error(Status::InvalidArgument, "def->min_distance: must not exceed the source's spacing");
    s.velocity = sph::Vec3{d.velocity.x, d.velocity.y, d.velocity.z};
    s.velocity_from_field = (d.flags & SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD) != 0;
    s.rate = d.rate;
    s.lattice = sph::lattice_inside(*s.region, s.spacing, kMaxSourceLatticePoints);
    require_room(world->world->sources().size(), "sources");
    out_id->bits = world->world->sources().insert(std::move(s));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_source_destroy(sph_world* world, sph_source_id id) {
  return sph::guarded("sph_source_destroy", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    return destroy_object(world, &sph::World::sources, id.bits, "id");
  });
}

SPH_API sph_result SPH_CALL sph_source_set_transform(sph_world* world, sph_source_id id,
                                                     const sph_transform* transform) {
  return sph::guarded("sph_source_set_transform", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    sph::Source* s = find_object(world->world->sources(), id.bits, "id");
    s->pose = read_transform(*transform, "transform");
    return SPH_OK;
  });
}

/* ---- sinks ---- */

SPH_API sph_result SPH_CALL sph_sink_def_init_sized(sph_sink_def* def, uint32_t size) {
  return sph::init_user_struct("sph_sink_def_init", "def", def, size, [](sph_sink_def& d) {
    d.mode = SPH_SINK_REGION;
    d.transform = to_public(identity());
  });
}

SPH_API sph_result SPH_CALL sph_sink_create(sph_world* world, const sph_sink_def* def, sph_sink_id* out_id) {
  return sph::guarded("sph_sink_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_sink_def d = sph::read_user_struct(def, "def");
    sph::require_zero(d.reserved0, "def->reserved0");
    sph::Sink s;
    const uint32_t mode = sph::enum_bits(d.mode);
    if (mode == SPH_SINK_REGION) {
      s.mode = sph::SinkMode::Region;
      s.region = require_world_sdf(world, d.region, "def->region");
      s.pose = read_transform(d.transform, "def->transform");
    } else if (mode == SPH_SINK_OUTSIDE_BOUNDS) {
      s.mode = sph::SinkMode::OutsideBounds;
      sph::require_finite_vec3(d.bounds_min, "def->bounds_min");
      sph::require_finite_vec3(d.bounds_max, "def->bounds_max");
      if (!(d.bounds_max.x >= d.bounds_min.x && d.bounds_max.y >= d.bounds_min.y &&
            d.bounds_max.z >= d.bounds_min.z))
        throw Error(Status::InvalidArgument, "def->bounds_max: every component must be >= def->bounds_min's");
      s.bounds_min = sph::Vec3{d.bounds_min.x, d.bounds_min.y, d.bounds_min.z};
      s.bounds_max = sph::Vec3{d.bounds_max.x, d.bounds_max.y, d.bounds_max.z};
      s.pose = identity();
    } else {
      throw Error(Status::Unsupported, "def->mode: " + std::to_string(static_cast<int32_t>(mode)) +
                                           " is not an sph_sink_mode value");
    }
    require_room(world->world->sinks().size(), "sinks");
    out_id->bits = world->world->sinks().insert(std::move(s));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sink_destroy(sph_world* world, sph_sink_id id) {
  return sph::guarded("sph_sink_destroy", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    return destroy_object(world, &sph::World::sinks, id.bits, "id");
  });
}

/* ---- force fields ---- */

SPH_API sph_result SPH_CALL sph_force_field_def_init_sized(sph_force_field_def* def, uint32_t size) {
  return sph::init_user_struct("sph_force_field_def_init", "def", def, size, [](sph_force_field_def& d) {
    d.kind = SPH_FORCE_FIELD_UNIFORM;
    d.transform = to_public(identity());
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
    sph::require_finite_vec3(d.vector, "def->vector");
    sph::require_finite(d.strength, "def->strength");
    sph::require_non_negative(d.falloff_radius, "def->falloff_radius");
    sph::ForceField f;
    f.kind = static_cast<sph::ForceFieldKind>(kind);
    f.pose = read_transform(d.transform, "def->transform");
    if (d.region) f.region = require_world_sdf(world, d.region, "def->region");
    f.vector = sph::Vec3{d.vector.x, d.vector.y, d.vector.z};
    if (f.kind == sph::ForceFieldKind::Vortex) {
      const float n = sph::length(f.vector);
      if (!(n > 0.0f)) throw Error(Status::InvalidArgument, "def->vector: a vortex needs a non-zero axis");
      f.vector = f.vector * (1.0f / n);
    }
    f.strength = d.strength;
    f.falloff_radius = d.falloff_radius;
    if (f.kind == sph::ForceFieldKind::Grid) {
      if (!d.grid) throw Error(Status::InvalidArgument, "def->grid: is NULL for a grid field");
      const sph_grid_desc g = sph::read_user_struct(d.grid, "def->grid");
      if (g.components != 3) throw Error(Status::InvalidArgument, "def->grid->components: must be 3");
      if (g.memory != SPH_MEMORY_HOST)
        throw Error(Status::Unsupported, "def->grid->memory: must be SPH_MEMORY_HOST");
      if (!g.data) throw Error(Status::InvalidArgument, "def->grid->data: is NULL");
      if (g.dims[0] == 0 || g.dims[1] == 0 || g.dims[2] == 0)
        throw Error(Status::InvalidArgument, "def->grid->dims: every dimension must be >= 1");
      const uint64_t n = static_cast<uint64_t>(g.dims[0]) * g.dims[1] * g.dims[2];
      if (n > (1ull << 28)) throw Error(Status::Capacity, "def->grid->dims: more than 2^28 voxels");
      sph::Affine3x4 affine;
      std::memcpy(affine.m, g.index_to_local, sizeof affine.m);
      auto grid =
          std::make_shared<sph::SdfAsset>(static_cast<int32_t>(g.dims[0]), static_cast<int32_t>(g.dims[1]),
                                          static_cast<int32_t>(g.dims[2]), affine);
      grid->velocity().resize(n);
      for (uint64_t i = 0; i < 3 * n; ++i)
        if (!std::isfinite(g.data[i]))
          throw Error(Status::InvalidArgument, "def->grid->data[" + std::to_string(i) + "]: is not finite");
      std::memcpy(grid->velocity().data(), g.data, 3 * n * sizeof(float));
      f.grid = std::move(grid);
    }
    require_room(world->world->force_fields().size(), "force fields");
    out_id->bits = world->world->force_fields().insert(std::move(f));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_force_field_destroy(sph_world* world, sph_force_field_id id) {
  return sph::guarded("sph_force_field_destroy", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    return destroy_object(world, &sph::World::force_fields, id.bits, "id");
  });
}

SPH_API sph_result SPH_CALL sph_force_field_set_transform(sph_world* world, sph_force_field_id id,
                                                          const sph_transform* transform) {
  return sph::guarded("sph_force_field_set_transform", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!transform) throw Error(Status::InvalidArgument, "transform: is NULL");
    sph::ForceField* f = find_object(world->world->force_fields(), id.bits, "id");
    f->pose = read_transform(*transform, "transform");
    return SPH_OK;
  });
}

/* ---- events ---- */

SPH_API sph_result SPH_CALL sph_world_get_events(const sph_world* world, sph_event* events, uint32_t capacity,
                                                 uint32_t* out_count) {
  return sph::guarded("sph_world_get_events", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    std::vector<sph_event> list;
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
    const std::vector<uint32_t>& removed = world->world->removed_ids();
    return copy_list(removed.data(), removed.size(), ids, capacity, out_count, "ids");
  });
}

}  // extern "C"
