// SPDX-License-Identifier: MIT
// Triangle meshes from files for mesh shapes: Wavefront OBJ (v and f records; polygons are
// fanned into triangles; other records ignored) and STL (binary, or ASCII "solid ... facet
// ... vertex"): read_mesh_file chooses by the file's extension, parse_mesh parses bytes already
// in memory (the fuzz harness tests/fuzz/fuzz_mesh.cpp).
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

enum class MeshFormat { kObj, kStl };

// Reads `path` (a regular file; .obj or .stl, any case) and scales every coordinate by `scale`.
// Throws std::runtime_error saying what is wrong and where (line or triangle).
MeshData read_mesh_file(const std::string& path, float scale);

// What read_mesh_file does once it has the file's bytes: parses `bytes` as `format` and scales
// every coordinate by `scale`. A mesh that comes back has at least one triangle, every index
// below the vertex count and every coordinate finite. Throws std::runtime_error whose message
// begins with `name_for_errors` (read_mesh_file passes the path) and says what is wrong and where.
MeshData parse_mesh(const std::string& bytes, MeshFormat format, float scale,
                    const std::string& name_for_errors);

}  // namespace sph_tools

#endif
