// SPDX-License-Identifier: MIT
// A triangle mesh (the fluid surface) drawn with a depth buffer and smooth normals.
#ifndef SPH_TOOLS_MESH_RASTER_H
#define SPH_TOOLS_MESH_RASTER_H

#include "camera.h"
#include "image.h"
#include "surface_mesh.h"

namespace sph_tools {

void raster_mesh(const SurfaceMesh& mesh, const Camera& camera, float near_depth, float far_depth,
                 Image* image);

}  // namespace sph_tools

#endif
