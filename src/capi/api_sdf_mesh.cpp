// SPDX-License-Identifier: MIT
// SDF assets from triangle meshes: the C layer over core/mesh_sdf.
#include <algorithm>

#include "../core/mesh_sdf.h"
#include "../core/sdf_limits.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

extern "C" {

SPH_API sph_result SPH_CALL sph_mesh_desc_init_sized(sph_mesh_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_mesh_desc_init", "desc", desc, size, [](sph_mesh_desc& d) {
    const sph::MeshSpec defaults;
    d.vertex_stride = static_cast<uint32_t>(defaults.vertex_stride);
    d.voxel_size = defaults.voxel_size;
    d.band_width = defaults.band_width;
    d.padding_voxels = static_cast<uint32_t>(defaults.padding_voxels);
  });
}

SPH_API sph_result SPH_CALL sph_sdf_create_from_mesh(sph_context* context, const sph_mesh_desc* desc,
                                                     sph_sdf** out) {
  return sph::guarded("sph_sdf_create_from_mesh", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph_mesh_desc d = sph::read_user_struct(desc, "desc");
    sph::require_zero(d.reserved0, "desc->reserved0");
    // Zero means default for every size; the arrays and counts are required (core names them).
    const sph::MeshSpec defaults;
    sph::MeshSpec spec;
    spec.vertices = d.vertices;
    spec.vertex_stride = d.vertex_stride == 0 ? defaults.vertex_stride : d.vertex_stride;
    spec.vertex_count = d.vertex_count;
    spec.indices = d.indices;
    spec.index_count = d.index_count;
    spec.voxel_size = d.voxel_size == 0.0f ? defaults.voxel_size : d.voxel_size;
    spec.band_width = d.band_width == 0.0f ? defaults.band_width : d.band_width;
    spec.padding_voxels = d.padding_voxels == 0
                              ? defaults.padding_voxels
                              : static_cast<int32_t>(std::min<uint32_t>(d.padding_voxels, 1u << 20));
    auto handle = std::make_unique<sph_sdf>();
    handle->context = hold.get();
    handle->asset = sph::build_mesh_sdf(spec, sph::kMaxSdfVoxels);
    *out = sph::publish_sdf(std::move(handle));
    return SPH_OK;
  });
}

}  // extern "C"
