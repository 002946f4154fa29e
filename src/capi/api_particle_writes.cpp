// SPDX-License-Identifier: MIT
// Writing particles already in a world: attribute ranges and removal by id (World checks the
// values; this layer checks the caller's buffers and copies them in).
#include <cstring>
#include <vector>

#include "../core/field_error.h"
#include "guard.h"
#include "handles.h"
#include "validate.h"

using sph::HostVector;

using sph::Error;
using sph::Status;

namespace {

template <class T>
HostVector<T> read_elements(const void* src, uint64_t stride, uint32_t count) {
  HostVector<T> out(count);
  const unsigned char* base = static_cast<const unsigned char*>(src);
  for (uint32_t i = 0; i < count; ++i) std::memcpy(&out[i], base + stride * i, sizeof(T));
  return out;
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_world_set_attribute(sph_world* world, sph_attribute attribute,
                                                    const void* src, uint64_t src_size, uint64_t src_stride,
                                                    uint32_t first, uint32_t count) {
  return sph::guarded("sph_world_set_attribute", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const uint32_t bits = sph::enum_bits(attribute);
    if (bits >= SPH_ATTRIBUTE_COUNT)
      throw Error(Status::Unsupported, "attribute: " + std::to_string(static_cast<int32_t>(bits)) +
                                           " is not an sph_attribute value");
    const bool vector = attribute == SPH_ATTRIBUTE_POSITION || attribute == SPH_ATTRIBUTE_VELOCITY;
    if (!vector && attribute != SPH_ATTRIBUTE_USER)
      throw Error(Status::InvalidArgument,
                  "attribute: only SPH_ATTRIBUTE_POSITION, SPH_ATTRIBUTE_VELOCITY and SPH_ATTRIBUTE_USER are "
                  "writable (the library computes density and pressure, and ids are its own)");
    if (attribute == SPH_ATTRIBUTE_USER) sph::require_user_attribute(world);
    sph::World& w = *world->world;
    w.require_particle_range(first, count);
    if (count == 0) return SPH_OK;
    if (!src) throw Error(Status::InvalidArgument, "src: is NULL but count is " + std::to_string(count));
    const uint64_t element = vector ? 3 * sizeof(float) : sizeof(uint32_t);
    const uint64_t stride = src_stride == 0 ? element : src_stride;
    if (stride < element)
      throw Error(Status::InvalidArgument, "src_stride: " + std::to_string(src_stride) +
                                               " is smaller than the element size " +
                                               std::to_string(element));
    const uint64_t needed = sph::require_array_span(src, count, stride, element, "src_stride");
    if (src_size < needed)
      throw Error(Status::BufferTooSmall, "src_size: " + std::to_string(src_size) + " bytes cannot hold " +
                                              std::to_string(count) + " elements at stride " +
                                              std::to_string(stride) + " (" + std::to_string(needed) +
                                              " bytes needed)");
    if (vector) {
      const HostVector<sph::Vec3> values = read_elements<sph::Vec3>(src, stride, count);
      w.set_vectors(static_cast<sph::AttributeKind>(attribute), first, values);
    } else {
      w.set_user_attributes(first, read_elements<uint32_t>(src, stride, count));
    }
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_remove_particles(sph_world* world, const uint32_t* ids,
                                                       uint32_t count) {
  return sph::guarded("sph_world_remove_particles", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (count == 0) return SPH_OK;
    if (!ids) throw Error(Status::InvalidArgument, "ids: is NULL but count is " + std::to_string(count));
    world->world->remove_particles(HostVector<uint32_t>(ids, ids + count));
    return SPH_OK;
  });
}

}  // extern "C"
