// SPDX-License-Identifier: MIT
// Loads on colliders (SPH_FEATURE_COLLIDER_LOADS): the last step's force and torque of the fluid
// on a collider, and the point the torque is about. The backends sum the impulses
// (physics/collider_loads.h); the world keeps each collider's averages (core/world.cpp).
#include "../core/field_error.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "public_vec3.h"
#include "struct_io.h"

using sph::Error;
using sph::Status;
using sph::to_public;

namespace {

void require_loads(const sph_world* world) {
  if (!(world->world->config().features & sph::kFeatureColliderLoads))
    throw Error(Status::FeatureDisabled,
                "world: SPH_FEATURE_COLLIDER_LOADS is not enabled in its sph_world_def");
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_collider_loads_init_sized(sph_collider_loads* loads, uint32_t size) {
  return sph::init_user_struct("sph_collider_loads_init", "loads", loads, size);
}

SPH_API sph_result SPH_CALL sph_collider_get_loads(const sph_world* world, sph_collider_id id,
                                                   sph_collider_loads* out) {
  return sph::guarded("sph_collider_get_loads", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::Collider& c = world->world->collider(id.bits);
    require_loads(world);
    sph_collider_loads o = sph::zeroed_struct<sph_collider_loads>();
    o.force = to_public(c.loads.force);
    o.torque = to_public(c.loads.torque);
    o.point = to_public(c.loads.time > 0.0 ? c.loads.point : sph::to_world(c.pose, c.load_point));
    o.frame_time = c.loads.time;
    sph::write_output_struct(out, o, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_set_load_point(sph_world* world, sph_collider_id id,
                                                        const sph_vec3* point) {
  return sph::guarded("sph_collider_set_load_point", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    world->world->collider(id.bits);  // the handle first: a stale id is INVALID_HANDLE
    require_loads(world);
    if (!point) throw Error(Status::InvalidArgument, "point: is NULL");
    world->world->set_collider_load_point(id.bits, sph::Vec3{point->x, point->y, point->z});
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_collider_set_load_threshold(sph_world* world, sph_collider_id id,
                                                            float force) {
  return sph::guarded("sph_collider_set_load_threshold", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    world->world->collider(id.bits);  // the handle first: a stale id is INVALID_HANDLE
    require_loads(world);
    world->world->set_collider_load_threshold(id.bits, force);
    return SPH_OK;
  });
}

}  // extern "C"
