// SPDX-License-Identifier: MIT
// Triangle meshes from files for mesh shapes: Wavefront OBJ (v and f records; polygons are
// fanned into triangles; other records ignored) and STL (binary, or ASCII "solid ... facet
// ... vertex"), chosen by the file's extension.
#ifndef SPH_TOOLS_MESH_FILE_H
#define SPH_TOOLS_MESH_FILE_H

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace sph_tools {

struct MeshData {
  std::vector<float> vertices;    // x, y, z per vertex
  std::vector<uint32_t> indices;  // three per triangle
};

// Reads `path` (a regular file; .obj or .stl, any case) and scales every coordinate by `scale`.
// Throws std::runtime_error saying what is wrong and where (line or triangle).
MeshData read_mesh_file(const std::string& path, float scale);

}  // namespace sph_tools

#endif
