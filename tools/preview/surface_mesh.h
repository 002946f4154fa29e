// SPDX-License-Identifier: MIT
// A triangle mesh of the fluid surface (from the level set), shared by the OBJ writer and the
// preview renderer.
#ifndef SPH_TOOLS_SURFACE_MESH_H
#define SPH_TOOLS_SURFACE_MESH_H

#include <cstdint>
#include <vector>

namespace sph_tools {

struct SurfaceMesh {
  std::vector<float> vertices;      // 3 x vertex count, m
  std::vector<uint32_t> triangles;  // 3 x triangle count, counter-clockwise seen from outside
};

}  // namespace sph_tools

#endif
