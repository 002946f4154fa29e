// SPDX-License-Identifier: MIT
// SDF assets: grids from the caller, analytic shapes, sub-box updates.
#include <vector>

#include "../core/field_checks.h"
#include "../core/sdf_limits.h"
#include "../core/sdf_shapes.h"
#include "grid_from_public.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

sph::LogTarget context_of_sdf(const sph_sdf* sdf) { return sph::log_target_of(sdf); }

// Copies `count` floats from caller memory (host or device) and checks they are finite.
// `name` is the grid's path with its separator ("desc->distance.", "desc->velocity->");
// `memory_bits` is the caller's sph_memory_kind read as an integer (sph::enum_bits): loading an
// out-of-range value as the enum type is undefined behaviour.
sph::HostVector<float> read_floats(const sph_context* context, const float* data, uint64_t count,
                                   uint32_t memory_bits, const std::string& name) {
  if (!data) throw Error(Status::InvalidArgument, name + "data: is NULL (required)");
  sph::HostVector<float> out(count);
  if (memory_bits == SPH_MEMORY_HOST) {
    std::memcpy(out.data(), data, count * sizeof(float));
  } else if (memory_bits == SPH_MEMORY_CUDA_DEVICE) {
    if (context->backend != sph::BackendKind::Cuda)
      throw Error(Status::Unsupported, name + "memory: device memory needs a CUDA context");
    sph::copy_device_to_host(out.data(), data, count * sizeof(float), context->device_ordinal);
  } else {
    throw Error(Status::Unsupported, name + "memory: " + std::to_string(static_cast<int32_t>(memory_bits)) +
                                         " is not an sph_memory_kind value");
  }
  for (uint64_t i = 0; i < count; ++i)
    if (!std::isfinite(out[i]))
      throw Error(Status::InvalidArgument, name + "data[" + std::to_string(i) + "]: is not finite");
  return out;
}

// A velocity channel's values (x, y, z a voxel): speeds below 1.8e19 m/s, as a particle's (a
// source with VELOCITY_FROM_FIELD gives its particles these; a faster one could never step).
void require_channel_speeds(const sph::HostVector<float>& xyz, const std::string& name) {
  for (size_t i = 0; i + 2 < xyz.size(); i += 3)
    if (!sph::speed_fits_float(sph::Vec3{xyz[i], xyz[i + 1], xyz[i + 2]}))
      throw Error(Status::InvalidArgument, name + "data[" + std::to_string(i) + ".." + std::to_string(i + 2) +
                                               "]: the speed's square overflows float32 (velocities must be "
                                               "below 1.8e19 m/s, as particles' are)");
}

uint64_t voxel_count(const uint32_t dims[3], const std::string& name) {
  if (dims[0] == 0 || dims[1] == 0 || dims[2] == 0)
    throw Error(Status::InvalidArgument, name + "dims: every dimension must be >= 1 (required)");
  const uint64_t n = static_cast<uint64_t>(dims[0]) * dims[1] * dims[2];
  if (n > sph::kMaxSdfVoxels || dims[0] > sph::kMaxSdfDim || dims[1] > sph::kMaxSdfDim ||
      dims[2] > sph::kMaxSdfDim)
    throw Error(Status::Capacity, name + "dims: more than 2^31 voxels");
  return n;
}

// Builds an asset from a caller description (validated as a whole before anything is kept).
std::shared_ptr<sph::SdfAsset> asset_from_desc(const sph_context* context, const sph_sdf_desc& d) {
  sph::require_zero(d.reserved0, "desc->reserved0");
  // The distance grid is embedded in sph_sdf_desc, so the outer struct's layout fixes its size:
  // the bytes after it are the outer struct's next fields (and past the end of our copy of it),
  // never the tail of a newer grid desc. Only this version's size can be right.
  // Zero (a zeroed sph_sdf_desc) means this version's size too.
  const uint32_t grid_size = d.distance.struct_size;
  if (grid_size != 0 && grid_size != sizeof(sph_grid_desc))
    throw Error(grid_size < sizeof(sph_grid_desc) ? Status::VersionMismatch : Status::Unsupported,
                "desc->distance.struct_size: " + std::to_string(grid_size) + " is not " +
                    std::to_string(sizeof(sph_grid_desc)) + " (or 0); fill it with sph_grid_desc_init()");
  const sph_grid_desc g = d.distance;
  if (sph::grid_components(g, 1) != 1)
    throw Error(Status::InvalidArgument, "desc->distance.components: must be 1 (or 0, meaning 1)");
  const uint64_t n = voxel_count(g.dims, "desc->distance.");
  if (!g.data) throw Error(Status::InvalidArgument, "desc->distance.data: is NULL (required)");
  auto asset = sph::make_grid_asset(g, "desc->distance.");
  asset->distance() = read_floats(context, g.data, n, sph::enum_bits(g.memory), "desc->distance.");
  auto same_dims = [&](const sph_grid_desc& o, const char* name) {
    if (o.dims[0] != g.dims[0] || o.dims[1] != g.dims[1] || o.dims[2] != g.dims[2])
      throw Error(Status::InvalidArgument, std::string(name) + "->dims: must equal desc->distance.dims");
  };
  if (d.velocity) {
    const sph_grid_desc v = sph::read_user_struct(d.velocity, "desc->velocity");
    same_dims(v, "desc->velocity");
    if (sph::grid_components(v, 3) != 3)
      throw Error(Status::InvalidArgument, "desc->velocity->components: must be 3 (or 0, meaning 3)");
    const sph::HostVector<float> raw =
        read_floats(context, v.data, 3 * n, sph::enum_bits(v.memory), "desc->velocity->");
    require_channel_speeds(raw, "desc->velocity->");
    asset->velocity().resize(n);
    std::memcpy(asset->velocity().data(), raw.data(), raw.size() * sizeof(float));
  }
  if (d.friction) {
    const sph_grid_desc f = sph::read_user_struct(d.friction, "desc->friction");
    same_dims(f, "desc->friction");
    if (sph::grid_components(f, 1) != 1)
      throw Error(Status::InvalidArgument, "desc->friction->components: must be 1 (or 0, meaning 1)");
    asset->friction() = read_floats(context, f.data, n, sph::enum_bits(f.memory), "desc->friction->");
    for (float mu : asset->friction())
      if (mu < 0.0f) throw Error(Status::InvalidArgument, "desc->friction->data: coefficients must be >= 0");
  }
  return asset;
}

sph_result publish(const sph::ContextHold& hold, std::shared_ptr<sph::SdfAsset> asset, sph_sdf** out) {
  auto handle = std::make_unique<sph_sdf>();
  handle->context = hold.get();
  handle->asset = std::move(asset);
  *out = sph::publish_sdf(std::move(handle));
  return SPH_OK;
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_grid_desc_init_sized(sph_grid_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_grid_desc_init", "desc", desc, size, [](sph_grid_desc& d) {
    d.index_to_local[0] = d.index_to_local[5] = d.index_to_local[10] = 1.0f;
    d.memory = SPH_MEMORY_HOST;
    d.components = 0;  // the channel's own count
  });
}

SPH_API sph_result SPH_CALL sph_sdf_desc_init_sized(sph_sdf_desc* desc, uint32_t size) {
  return sph::guarded("sph_sdf_desc_init", nullptr, [&] {
    sph::require_init_size(desc, size, "desc");
    sph_sdf_desc d;
    std::memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    sph_grid_desc_init(&d.distance);
    sph::write_user_struct(desc, size, d);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_shape_desc_init_sized(sph_shape_desc* desc, uint32_t size) {
  return sph::guarded("sph_shape_desc_init", nullptr, [&] {
    sph::require_init_size(desc, size, "desc");
    const sph::ShapeSpec defaults;
    sph_shape_desc d;
    std::memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.shape = SPH_SHAPE_BOX;
    d.half_extents = sph_vec3{defaults.half_extents.x, defaults.half_extents.y, defaults.half_extents.z};
    d.radius = defaults.radius;
    d.half_height = defaults.half_height;
    d.wall_thickness = 0.0f;
    d.voxel_size = defaults.voxel_size;
    sph::write_user_struct(desc, size, d);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sdf_create(sph_context* context, const sph_sdf_desc* desc, sph_sdf** out) {
  return sph::guarded("sph_sdf_create", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph_sdf_desc d = sph::read_user_struct(desc, "desc");
    return publish(hold, asset_from_desc(hold.get(), d), out);
  });
}

SPH_API sph_result SPH_CALL sph_sdf_create_shape(sph_context* context, const sph_shape_desc* desc,
                                                 sph_sdf** out) {
  return sph::guarded("sph_sdf_create_shape", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph_shape_desc d = sph::read_user_struct(desc, "desc");
    const uint32_t shape = sph::enum_bits(d.shape);
    if (shape > SPH_SHAPE_CUP)
      throw Error(Status::Unsupported, "desc->shape: " + std::to_string(static_cast<int32_t>(shape)) +
                                           " is not an sph_shape value");
    if (d.flags & ~SPH_SHAPE_FLAG_OPEN_TOP) throw Error(Status::Unsupported, "desc->flags: unknown bits");
    sph::require_finite_vec3(d.half_extents, "desc->half_extents");
    sph::require_finite(d.radius, "desc->radius");
    sph::require_finite(d.half_height, "desc->half_height");
    sph::require_non_negative(d.wall_thickness, "desc->wall_thickness");
    // Zero means default for every size (a zeroed desc is a plane of the default sizes).
    const sph::ShapeSpec defaults;
    auto or_default = [](float value, float fallback) { return value == 0.0f ? fallback : value; };
    sph::ShapeSpec spec;
    spec.kind = static_cast<sph::ShapeKind>(shape);
    spec.half_extents = sph::Vec3{or_default(d.half_extents.x, defaults.half_extents.x),
                                  or_default(d.half_extents.y, defaults.half_extents.y),
                                  or_default(d.half_extents.z, defaults.half_extents.z)};
    spec.radius = or_default(d.radius, defaults.radius);
    spec.half_height = or_default(d.half_height, defaults.half_height);
    spec.wall_thickness = d.wall_thickness;
    spec.open_top = (d.flags & SPH_SHAPE_FLAG_OPEN_TOP) != 0;
    spec.voxel_size = or_default(d.voxel_size, defaults.voxel_size);
    sph::require_positive(spec.voxel_size, "desc->voxel_size");
    spec.padding_voxels =
        d.padding_voxels == 0 ? 4 : static_cast<int32_t>(std::min<uint32_t>(d.padding_voxels, 1u << 20));
    return publish(hold, sph::build_shape_sdf(spec, sph::kMaxSdfVoxels), out);
  });
}

SPH_API sph_result SPH_CALL sph_sdf_update(sph_sdf* sdf, sph_sdf_channel channel, const uint32_t origin[3],
                                           const uint32_t size[3], const float* data,
                                           sph_memory_kind memory) {
  return sph::guarded("sph_sdf_update", context_of_sdf(sdf), [&] {
    const sph::SdfUse use = sph::use_sdf(sdf, "sdf");
    if (!origin) throw Error(Status::InvalidArgument, "origin: is NULL");
    if (!size) throw Error(Status::InvalidArgument, "size: is NULL");
    uint32_t components;
    const uint32_t channel_bits = sph::enum_bits(channel);
    switch (channel_bits) {
      case SPH_SDF_CHANNEL_DISTANCE:
        components = 1;
        break;
      case SPH_SDF_CHANNEL_VELOCITY:
        components = 3;
        break;
      case SPH_SDF_CHANNEL_FRICTION:
        components = 1;
        break;
      default:
        throw Error(Status::Unsupported, "channel: " + std::to_string(static_cast<int32_t>(channel_bits)) +
                                             " is not an sph_sdf_channel value");
    }
    sph::SdfAsset& a = *use.asset;
    const uint32_t dims[3] = {static_cast<uint32_t>(a.nx()), static_cast<uint32_t>(a.ny()),
                              static_cast<uint32_t>(a.nz())};
    for (int axis = 0; axis < 3; ++axis)
      if (size[axis] == 0 || origin[axis] >= dims[axis] || size[axis] > dims[axis] - origin[axis])
        throw Error(Status::InvalidArgument,
                    "origin, size: the box [" + std::to_string(origin[axis]) + ", " +
                        std::to_string(static_cast<uint64_t>(origin[axis]) + size[axis]) +
                        ") leaves the grid along axis " + std::to_string(axis) + " (dimension " +
                        std::to_string(dims[axis]) + ")");
    const uint64_t n = static_cast<uint64_t>(size[0]) * size[1] * size[2];
    const sph::HostVector<float> values =
        read_floats(use.context.get(), data, n * components, sph::enum_bits(memory), "");
    if (channel_bits == SPH_SDF_CHANNEL_FRICTION)
      for (float mu : values)
        if (mu < 0.0f) throw Error(Status::InvalidArgument, "data: friction coefficients must be >= 0");
    if (channel_bits == SPH_SDF_CHANNEL_VELOCITY) require_channel_speeds(values, "");
    float* target = nullptr;
    if (channel_bits == SPH_SDF_CHANNEL_DISTANCE) {
      target = a.distance().data();
    } else if (channel_bits == SPH_SDF_CHANNEL_VELOCITY) {
      if (a.velocity().empty()) a.velocity().assign(a.voxel_count(), sph::Vec3{0.0f, 0.0f, 0.0f});
      target = &a.velocity()[0].x;
    } else {
      if (a.friction().empty()) a.friction().assign(a.voxel_count(), 0.0f);
      target = a.friction().data();
    }
    for (uint32_t k = 0; k < size[2]; ++k)
      for (uint32_t j = 0; j < size[1]; ++j) {
        const uint64_t row =
            (origin[0] + static_cast<uint64_t>(dims[0]) *
                             (origin[1] + j + static_cast<uint64_t>(dims[1]) * (origin[2] + k)));
        const uint64_t src = static_cast<uint64_t>(size[0]) * (j + static_cast<uint64_t>(size[1]) * k);
        std::memcpy(target + row * components, values.data() + src * components,
                    size[0] * components * sizeof(float));
      }
    // The box it changed, so that a boundary map recomputes only what it reaches (a velocity or
    // friction update: no distance changed).
    sph::VoxelBox changed;
    if (channel_bits == SPH_SDF_CHANNEL_DISTANCE)
      for (int axis = 0; axis < 3; ++axis) {
        changed.lo[axis] = static_cast<int32_t>(origin[axis]);
        changed.hi[axis] = static_cast<int32_t>(origin[axis] + size[axis]);
      }
    a.record_change(changed);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sdf_get_dims(const sph_sdf* sdf, uint32_t out_dims[3]) {
  return sph::guarded("sph_sdf_get_dims", context_of_sdf(sdf), [&] {
    const sph::SdfUse use = sph::use_sdf(sdf, "sdf");
    if (!out_dims) throw Error(Status::InvalidArgument, "out_dims: is NULL");
    out_dims[0] = static_cast<uint32_t>(use.asset->nx());
    out_dims[1] = static_cast<uint32_t>(use.asset->ny());
    out_dims[2] = static_cast<uint32_t>(use.asset->nz());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sdf_sample(const sph_sdf* sdf, sph_vec3 local_point, float* out_distance) {
  return sph::guarded("sph_sdf_sample", context_of_sdf(sdf), [&] {
    const sph::SdfUse use = sph::use_sdf(sdf, "sdf");
    sph::require_finite_vec3(local_point, "local_point");
    if (!out_distance) throw Error(Status::InvalidArgument, "out_distance: is NULL");
    *out_distance =
        sph::sample_distance(use.asset->host_view(), sph::Vec3{local_point.x, local_point.y, local_point.z});
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_sdf_destroy(sph_sdf* sdf) {
  if (!sdf) {
    sph::clear_last_error();
    return SPH_OK;
  }
  return sph::guarded("sph_sdf_destroy", context_of_sdf(sdf), [&] {
    // Calls in flight on the handle hold their own reference to the asset and its context.
    if (!sph::try_retire_sdf(sdf))
      throw Error(Status::InvalidHandle, "sdf: is not a live sph_sdf (destroyed or foreign pointer)");
    delete sdf;
    return SPH_OK;
  });
}

}  // extern "C"
