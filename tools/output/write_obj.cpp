// SPDX-License-Identifier: MIT
// The surface mesh as Wavefront OBJ with per-vertex normals (vn), so importers shade it smooth
// instead of faceted. Normals are the area-weighted mean of the adjacent faces' normals: the
// cross product of two edges is twice the face's area times its unit normal, so summing the
// raw cross products weights each face by its area.
#include <cmath>
#include <cstdio>

#include "new_file.h"
#include "writers.h"

namespace sph_tools {

void vertex_normals(const SurfaceMesh& mesh, std::vector<float>* normals) {
  normals->assign(mesh.vertices.size(), 0.0f);
  const std::vector<float>& v = mesh.vertices;
  for (size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    const size_t a = 3 * size_t{mesh.triangles[t]}, b = 3 * size_t{mesh.triangles[t + 1]},
                 c = 3 * size_t{mesh.triangles[t + 2]};
    const float e1[3] = {v[b] - v[a], v[b + 1] - v[a + 1], v[b + 2] - v[a + 2]};
    const float e2[3] = {v[c] - v[a], v[c + 1] - v[a + 1], v[c + 2] - v[a + 2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
    for (size_t corner : {a, b, c})
      for (int k = 0; k < 3; ++k) (*normals)[corner + static_cast<size_t>(k)] += n[k];
  }
  for (size_t i = 0; i < normals->size(); i += 3) {
    float* n = &(*normals)[i];
    const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (length > 0.0f) {
      n[0] /= length;
      n[1] /= length;
      n[2] /= length;
    }
  }
}

void write_obj(const SurfaceMesh& mesh, uint32_t frame, double time, const std::string& path) {
  std::vector<float> normals;
  vertex_normals(mesh, &normals);
  NewFile file(path);
  std::FILE* out = file.get();
  std::fprintf(out, "# sph-run fluid surface, frame %u, time %.9g s, %zu vertices, %zu triangles\n", frame,
               time, mesh.vertices.size() / 3, mesh.triangles.size() / 3);
  for (size_t i = 0; i < mesh.vertices.size(); i += 3)
    std::fprintf(out, "v %.7g %.7g %.7g\n", mesh.vertices[i], mesh.vertices[i + 1], mesh.vertices[i + 2]);
  for (size_t i = 0; i < normals.size(); i += 3)
    std::fprintf(out, "vn %.6g %.6g %.6g\n", normals[i], normals[i + 1], normals[i + 2]);
  for (size_t i = 0; i + 2 < mesh.triangles.size(); i += 3) {
    const uint32_t a = mesh.triangles[i] + 1, b = mesh.triangles[i + 1] + 1, c = mesh.triangles[i + 2] + 1;
    std::fprintf(out, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
  }
  file.close();
}

}  // namespace sph_tools
