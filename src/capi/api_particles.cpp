// SPDX-License-Identifier: MIT
// Particles in (spawn, lattice fills) and out (count, attribute copies).
#include <vector>

#include "../core/field_error.h"
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

sph::Vec3 read_vec3(const float* base, uint64_t stride, uint32_t i) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(base) + stride * i;
  float v[3];
  std::memcpy(v, p, sizeof v);
  return sph::Vec3{v[0], v[1], v[2]};
}

size_t element_size(sph_attribute a) {
  return (a == SPH_ATTRIBUTE_POSITION || a == SPH_ATTRIBUTE_VELOCITY) ? 3 * sizeof(float) : sizeof(float);
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_spawn_desc_init_sized(sph_spawn_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_spawn_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_fill_box_desc_init_sized(sph_fill_box_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_fill_box_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_fill_sphere_desc_init_sized(sph_fill_sphere_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_fill_sphere_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_world_spawn(sph_world* world, const sph_spawn_desc* desc,
                                            uint32_t* out_first_id) {
  return sph::guarded("sph_world_spawn", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_spawn_desc d = sph::read_user_struct(desc, "desc");
    if (d.count > 0 && !d.positions)
      throw Error(Status::InvalidArgument, "desc->positions: is NULL but desc->count is " +
                                               std::to_string(d.count) + " (positions are required)");
    const uint64_t pstride = d.position_stride == 0 ? 12 : d.position_stride;
    const uint64_t vstride = d.velocity_stride == 0 ? 12 : d.velocity_stride;
    if (pstride < 12) throw Error(Status::InvalidArgument, "desc->position_stride: must be 0 or >= 12");
    if (d.velocities && vstride < 12)
      throw Error(Status::InvalidArgument, "desc->velocity_stride: must be 0 or >= 12");
    sph::require_array_span(d.positions, d.count, pstride, 12, "desc->position_stride");
    if (d.velocities) sph::require_array_span(d.velocities, d.count, vstride, 12, "desc->velocity_stride");
    const uint32_t first = sph::with_field_prefix("desc->", [&] {
      world->world->require_room_for_particles(d.count);  // before copying a large input
      HostVector<sph::Vec3> positions(d.count);
      for (uint32_t i = 0; i < d.count; ++i) positions[i] = read_vec3(d.positions, pstride, i);
      HostVector<sph::Vec3> velocities;
      if (d.velocities) {
        velocities.resize(d.count);
        for (uint32_t i = 0; i < d.count; ++i) velocities[i] = read_vec3(d.velocities, vstride, i);
      }
      return world->world->add_particles(positions, d.velocities ? &velocities : nullptr);
    });
    if (out_first_id) *out_first_id = first;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_fill_box(sph_world* world, const sph_fill_box_desc* desc,
                                               uint32_t* out_count) {
  return sph::guarded("sph_world_fill_box", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_fill_box_desc d = sph::read_user_struct(desc, "desc");
    sph::require_zero(d.reserved0, "desc->reserved0");
    sph::FillBoxSpec spec;
    spec.min = vec3_from_public(d.min);
    spec.max = vec3_from_public(d.max);
    spec.velocity = vec3_from_public(d.velocity);
    const uint32_t n = sph::with_field_prefix("desc->", [&] { return world->world->fill_box(spec); });
    if (out_count) *out_count = n;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_fill_sphere(sph_world* world, const sph_fill_sphere_desc* desc,
                                                  uint32_t* out_count) {
  return sph::guarded("sph_world_fill_sphere", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_fill_sphere_desc d = sph::read_user_struct(desc, "desc");
    sph::require_zero(d.reserved0, "desc->reserved0");
    sph::FillSphereSpec spec;
    spec.center = vec3_from_public(d.center);
    spec.radius = d.radius;
    spec.velocity = vec3_from_public(d.velocity);
    const uint32_t n = sph::with_field_prefix("desc->", [&] { return world->world->fill_sphere(spec); });
    if (out_count) *out_count = n;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_particle_count(const sph_world* world, uint32_t* out_count) {
  return sph::guarded("sph_world_get_particle_count", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_count) throw Error(Status::InvalidArgument, "out_count: is NULL");
    *out_count = world->world->particle_count();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_copy_attribute(const sph_world* world, sph_attribute attribute,
                                                     void* dst, uint64_t dst_size, uint64_t dst_stride,
                                                     uint32_t first, uint32_t count, uint32_t* out_written) {
  return sph::guarded("sph_world_copy_attribute", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (sph::enum_bits(attribute) >= SPH_ATTRIBUTE_COUNT)
      throw Error(Status::Unsupported,
                  "attribute: " + std::to_string(static_cast<int32_t>(sph::enum_bits(attribute))) +
                      " is not an sph_attribute value");
    if (attribute == SPH_ATTRIBUTE_USER) sph::require_user_attribute(world);
    if (!dst) throw Error(Status::InvalidArgument, "dst: is NULL");
    const uint64_t element = element_size(attribute);
    const uint64_t stride = dst_stride == 0 ? element : dst_stride;
    if (stride < element)
      throw Error(Status::InvalidArgument, "dst_stride: " + std::to_string(dst_stride) +
                                               " is smaller than the element size " +
                                               std::to_string(element));
    const uint32_t total = world->world->particle_count();
    if (first > total)
      throw Error(Status::InvalidArgument, "first: " + std::to_string(first) +
                                               " is beyond the particle count " + std::to_string(total));
    const uint32_t n = std::min(count, total - first);
    const uint64_t needed = sph::require_array_span(dst, n, stride, element, "dst_stride");
    if (dst_size < needed)
      throw Error(Status::BufferTooSmall, "dst_size: " + std::to_string(dst_size) + " bytes cannot hold " +
                                              std::to_string(n) + " elements at stride " +
                                              std::to_string(stride) + " (" + std::to_string(needed) +
                                              " bytes needed)");
    if (n > 0)
      world->world->backend().copy_attribute(static_cast<sph::AttributeKind>(attribute), first, n, dst,
                                             stride);
    if (out_written) *out_written = n;
    return SPH_OK;
  });
}

}  // extern "C"
