// SPDX-License-Identifier: MIT
// Turning a ShapeDesc into an SDF asset of a context: sph_sdf_create_shape for analytic shapes,
// sph_vdb_load_sdf for .vdb level sets (when the tools are built with OpenVDB),
// sph_sdf_create_from_mesh for .obj and .stl meshes.
#ifndef SPH_TOOLS_SDF_FACTORY_H
#define SPH_TOOLS_SDF_FACTORY_H

#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

// A new asset the caller owns (sph_sdf_destroy). Throws SceneError at shape.path.
sph_sdf* create_sdf(sph_context* context, const ShapeDesc& shape);

// Whether .vdb shapes can be loaded (the tools were built with libsph_vdb).
bool vdb_shapes_supported();

// The box in the asset's local frame that holds the shape's surface (analytic shapes: exact;
// .vdb level sets: the active voxels' box when ShapeDesc has it, else false).
bool shape_local_bounds(const ShapeDesc& shape, sph_vec3* min, sph_vec3* max);

}  // namespace sph_tools

#endif
