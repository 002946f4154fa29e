// SPDX-License-Identifier: MIT
#include "sdf_factory.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "scene_error.h"
#ifdef SPH_TOOLS_HAVE_VDB
#include "sph_vdb.h"
#endif

namespace sph_tools {

bool vdb_shapes_supported() {
#ifdef SPH_TOOLS_HAVE_VDB
  return true;
#else
  return false;
#endif
}

sph_sdf* create_sdf(sph_context* context, const ShapeDesc& shape) {
  sph_sdf* sdf = nullptr;
  if (shape.kind == ShapeDesc::Kind::kVdb) {
#ifdef SPH_TOOLS_HAVE_VDB
    const sph_result r = sph_vdb_load_sdf(context, shape.vdb_file.c_str(),
                                          shape.vdb_grid.empty() ? nullptr : shape.vdb_grid.c_str(), &sdf);
    if (r < 0) {
      const char* why = sph_vdb_get_last_error();
      throw SceneError(shape.path + ".file", std::string("cannot load a level set from ") + shape.vdb_file +
                                                 ": " + (why && why[0] ? why : sph_result_string(r)));
    }
    return sdf;
#else
    (void)context;
    throw SceneError(shape.path + ".type",
                     "\"vdb\" shapes need tools built with OpenVDB (this build has none)");
#endif
  }
  if (shape.kind == ShapeDesc::Kind::kMesh) {
    sph_mesh_desc d = shape.mesh;
    d.vertices = shape.mesh_vertices.data();
    d.vertex_count = static_cast<uint32_t>(shape.mesh_vertices.size() / 3);
    d.indices = shape.mesh_indices.data();
    d.index_count = static_cast<uint32_t>(shape.mesh_indices.size());
    const sph_result r = sph_sdf_create_from_mesh(context, &d, &sdf);
    if (r < 0)
      throw SceneError(shape.path,
                       "the library rejected the mesh from " + shape.mesh_file + ": " + sph_get_last_error());
    return sdf;
  }
  const sph_result r = sph_sdf_create_shape(context, &shape.analytic, &sdf);
  if (r < 0)
    throw SceneError(shape.path, std::string("the library rejected the shape: ") + sph_get_last_error());
  return sdf;
}

bool shape_local_bounds(const ShapeDesc& shape, sph_vec3* min, sph_vec3* max) {
  if (shape.kind == ShapeDesc::Kind::kVdb) {
    *min = shape.vdb_bounds_min;
    *max = shape.vdb_bounds_max;
    return shape.has_vdb_bounds;
  }
  if (shape.kind == ShapeDesc::Kind::kMesh) {
    if (shape.mesh_vertices.empty()) return false;
    *min = sph_vec3{INFINITY, INFINITY, INFINITY};
    *max = sph_vec3{-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < shape.mesh_vertices.size(); i += 3) {
      const float* v = &shape.mesh_vertices[i];
      *min = sph_vec3{std::min(min->x, v[0]), std::min(min->y, v[1]), std::min(min->z, v[2])};
      *max = sph_vec3{std::max(max->x, v[0]), std::max(max->y, v[1]), std::max(max->z, v[2])};
    }
    return true;
  }
  const sph_shape_desc& d = shape.analytic;
  const float w = d.wall_thickness;
  sph_vec3 h{0.0f, 0.0f, 0.0f};
  switch (d.shape) {
    case SPH_SHAPE_PLANE:
      h = d.half_extents;
      break;
    case SPH_SHAPE_BOX:
      h = sph_vec3{d.half_extents.x + w, d.half_extents.y + w, d.half_extents.z + w};
      break;
    case SPH_SHAPE_SPHERE:
      h = sph_vec3{d.radius, d.radius, d.radius};
      break;
    case SPH_SHAPE_CAPSULE:
      h = sph_vec3{d.radius, d.half_height + d.radius, d.radius};
      break;
    case SPH_SHAPE_CYLINDER:
      h = sph_vec3{d.radius, d.half_height, d.radius};
      break;
    case SPH_SHAPE_CUP:
      h = sph_vec3{d.radius + w, d.half_height, d.radius + w};
      break;
    default:
      return false;
  }
  *min = sph_vec3{-h.x, -h.y, -h.z};
  *max = h;
  return true;
}

}  // namespace sph_tools
