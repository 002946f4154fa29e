// SPDX-License-Identifier: MIT
#include "sdf_factory.h"

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
