// SPDX-License-Identifier: MIT
// The zero-copy tier (include/sph_cuda.h): device addresses of attributes, the data epoch, the
// world's stream and event ordering. The backend answers; a CPU backend (and every backend of
// a build without CUDA) refuses with Unsupported.
#include <type_traits>

#include "guard.h"
#include "handles.h"
#include "sph_cuda.h"
#include "struct_io.h"

using sph::Error;
using sph::Status;

namespace {

// Runs a backend call; a sticky device error marks the world lost, as sph_world_step does.
template <class Body>
sph_result with_backend(const sph_world* world, Body&& body) {
  sph::require_world(world);
  sph::WorldLock lock(world);
  return sph::marking_device_lost(world, [&] { return body(world->world->backend()); });
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_cuda_attribute_view_init_sized(sph_cuda_attribute_view* view, uint32_t size) {
  return sph::guarded("sph_cuda_attribute_view_init", nullptr, [&] {
    sph::require_init_size(view, size, "view");
    sph_cuda_attribute_view v;
    std::memset(&v, 0, sizeof v);
    v.struct_size = sizeof v;
    sph::write_user_struct(view, size, v);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_get_attribute(const sph_world* world, sph_attribute attribute,
                                                         sph_cuda_attribute_view* out) {
  return sph::guarded("sph_cuda_world_get_attribute", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
      if (static_cast<uint32_t>(attribute) >= SPH_ATTRIBUTE_COUNT)
        throw Error(Status::Unsupported, "attribute: " + std::to_string(static_cast<int>(attribute)) +
                                             " is not an sph_attribute value");
      if (attribute == SPH_ATTRIBUTE_USER) sph::require_user_attribute(world);
      const sph::DeviceAttributeView d = backend.device_attribute(static_cast<sph::AttributeKind>(attribute));
      sph_cuda_attribute_view v;
      std::memset(&v, 0, sizeof v);
      v.struct_size = sizeof v;
      v.attribute = attribute;
      v.device_address = d.address;
      v.stride = d.stride;
      v.element_size = d.element_size;
      v.count = d.count;
      v.epoch = d.epoch;
      v.device_ordinal = d.device;
      sph::write_output_struct(out, v, "out");
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_get_epoch(const sph_world* world, uint64_t* out_epoch) {
  return sph::guarded("sph_cuda_world_get_epoch", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!out_epoch) throw Error(Status::InvalidArgument, "out_epoch: is NULL");
      *out_epoch = backend.data_epoch();
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_get_device(const sph_world* world, int32_t* out_device_ordinal) {
  return sph::guarded("sph_cuda_world_get_device", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!out_device_ordinal) throw Error(Status::InvalidArgument, "out_device_ordinal: is NULL");
      *out_device_ordinal = backend.device_ordinal();
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_get_stream(const sph_world* world, void** out_stream) {
  return sph::guarded("sph_cuda_world_get_stream", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!out_stream) throw Error(Status::InvalidArgument, "out_stream: is NULL");
      *out_stream = backend.device_stream();
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_record_event(sph_world* world, void* event) {
  return sph::guarded("sph_cuda_world_record_event", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!event) throw Error(Status::InvalidArgument, "event: is NULL");
      backend.record_device_event(event);
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_world_wait_event(sph_world* world, void* event) {
  return sph::guarded("sph_cuda_world_wait_event", sph::context_of(world), [&] {
    return with_backend(world, [&](const sph::Backend& backend) {
      if (!event) throw Error(Status::InvalidArgument, "event: is NULL");
      backend.wait_device_event(event);
      return SPH_OK;
    });
  });
}

SPH_API sph_result SPH_CALL sph_cuda_allocator_init_sized(sph_cuda_allocator* allocator, uint32_t size) {
  return sph::guarded("sph_cuda_allocator_init", nullptr, [&] {
    sph::require_init_size(allocator, size, "allocator");
    sph_cuda_allocator a;
    std::memset(&a, 0, sizeof a);
    a.struct_size = sizeof a;
    sph::write_user_struct(allocator, size, a);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_cuda_context_set_allocator(sph_context* context,
                                                           const sph_cuda_allocator* allocator) {
  return sph::guarded("sph_cuda_context_set_allocator", context, [&] {
    sph::DeviceMemoryHooks hooks;
    if (allocator) {
      const sph_cuda_allocator a = sph::read_user_struct(allocator, "allocator");
      if (a.reserved0 != 0) throw Error(Status::InvalidArgument, "allocator->reserved0: must be 0");
      if ((a.alloc_fn == nullptr) != (a.free_fn == nullptr))
        throw Error(Status::InvalidArgument, a.alloc_fn
                                                 ? "allocator->free_fn: is NULL while alloc_fn is set; "
                                                   "give both (the engine's allocator) or neither"
                                                 : "allocator->alloc_fn: is NULL while free_fn is set; "
                                                   "give both (the engine's allocator) or neither");
      if (!a.alloc_fn && a.user_context)
        throw Error(Status::InvalidArgument, "allocator->user_context: is set without alloc_fn and free_fn");
      hooks.alloc = a.alloc_fn;
      hooks.free = a.free_fn;
      hooks.user_context = a.user_context;
    }
    {
      const sph::ContextHold hold(context);
      if (hold.get()->backend != sph::BackendKind::Cuda)
        throw Error(Status::Unsupported,
                    "context: is not a CUDA context (device allocators are for CUDA worlds)");
    }
    std::string why;
    const sph::Take take = sph::try_set_device_memory(context, hooks, &why);
    if (take == sph::Take::NotLive)
      throw Error(Status::InvalidHandle, "context: is not a live sph_context (destroyed or foreign pointer)");
    if (take == sph::Take::Busy) throw Error(Status::Busy, "context: " + why);
    return SPH_OK;
  });
}

static_assert(std::is_same<sph_cuda_alloc_fn, decltype(sph::DeviceMemoryHooks::alloc)>::value,
              "the device allocator types match");
static_assert(std::is_same<sph_cuda_free_fn, decltype(sph::DeviceMemoryHooks::free)>::value,
              "the device allocator types match");

}  // extern "C"
