// SPDX-License-Identifier: MIT
// libFuzzer harness: the input is a mesh file of a scene's "mesh" shape (tools/scene/mesh_file).
// The first byte picks the format (bit 0: OBJ or STL), the scale (bits 1-3), the way to the SDF
// (bit 4: sph-run's sdf_factory or sph_sdf_create_from_mesh itself), the padding (bits 5-6) and
// the band width (bit 7); the rest is the file's bytes. parse_mesh must either return a mesh
// (at least one triangle, every index below the vertex count, every coordinate finite) or throw
// std::runtime_error with a message that names the file; anything else (another exception, a
// crash, undefined behaviour) is a bug. A mesh that parses is built into an SDF asset at a voxel
// size that keeps the grid small (its cost is about voxels x triangles), which may fail with
// SceneError (sdf_factory) or INVALID_ARGUMENT (the C call: fewer than three vertices, a voxel
// size that overflows float) and must not write *out or leave any library object alive.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "fuzz_check.h"
#include "mesh_file.h"
#include "scene_desc.h"
#include "scene_error.h"
#include "sdf_factory.h"
#include "sph_c.h"

using sph_fuzz::create_cpu_context;
using sph_fuzz::violation;

namespace {

const char kName[] = "fuzz-input";
// Scales a scene may give ("scale": positive): ordinary ones and the extremes of float.
const float kScales[8] = {1.0f,     2.0f,    1.0e-3f, 1.0e3f,
                          1.0e-30f, 1.0e30f, 3.0e38f, std::numeric_limits<float>::denorm_min()};
const uint32_t kPaddings[4] = {0, 1, 2, 8};  // 0: the default (4)
// The budget of one build: voxels x (triangles + 16). Under the sanitizers and the coverage
// instrumentation a voxel costs about 12 us (the far-field sweeps' 16 passes) and a voxel-triangle
// pair about 1 us (the band pass and the winding number), so a build takes at most about 60 ms.
constexpr double kMaxWork = 1 << 16;

uint32_t live_objects() {
  uint32_t n = 0;
  FUZZ_CALL(sph_get_live_object_count(&n));
  return n;
}

// The library's grid for `voxel` (0: its default) over the box [lo, hi], an upper bound per
// axis (src/core/mesh_sdf.cpp: ceil(extent / voxel) + 2 padding + 1, in double).
double grid_voxels(const double lo[3], const double hi[3], float voxel, uint32_t padding) {
  const double v = voxel == 0.0f ? 0.01 : static_cast<double>(voxel);
  const double pad = padding == 0 ? 4.0 : static_cast<double>(padding);
  double voxels = 1.0;
  for (int a = 0; a < 3; ++a) voxels *= std::ceil((hi[a] - lo[a]) / v) + 2.0 * pad + 2.0;
  return voxels;
}

void check_mesh(const sph_tools::MeshData& m) {
  if (m.vertices.size() % 3 != 0)
    violation("%zu vertex coordinates, not three per vertex", m.vertices.size());
  if (m.indices.empty() || m.indices.size() % 3 != 0)
    violation("%zu indices, not a positive multiple of three", m.indices.size());
  const size_t count = m.vertices.size() / 3;
  for (size_t i = 0; i < m.indices.size(); ++i)
    if (m.indices[i] >= count)
      violation("index %zu is %u, not below the vertex count %zu", i, m.indices[i], count);
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (!std::isfinite(m.vertices[i])) violation("coordinate %zu is %g after scaling", i, m.vertices[i]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t options = data[0];
  const sph_tools::MeshFormat format =
      (options & 1) ? sph_tools::MeshFormat::kStl : sph_tools::MeshFormat::kObj;
  const float scale = kScales[(options >> 1) & 7];
  const bool through_factory = (options & 0x10) == 0;
  const uint32_t padding = kPaddings[(options >> 5) & 3];
  const float band = (options & 0x80) ? 1.0f : 0.0f;  // 0: the default (3)
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);

  sph_tools::MeshData mesh;
  try {
    mesh = sph_tools::parse_mesh(bytes, format, scale, kName);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    const std::string prefix = std::string(kName) + ": ";
    if (what.size() <= prefix.size() || what.compare(0, prefix.size(), prefix) != 0)
      violation("the parse error \"%s\" does not begin with the file's name and say why", what.c_str());
    return 0;
  }
  check_mesh(mesh);

  // The box of the vertices the triangles use (what the library bounds), and the most voxels
  // across it that keep the build within the budget.
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = INFINITY, hi[a] = -INFINITY;
  for (uint32_t index : mesh.indices)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<double>(mesh.vertices[3 * index + a]));
      hi[a] = std::max(hi[a], static_cast<double>(mesh.vertices[3 * index + a]));
    }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double triangles = static_cast<double>(mesh.indices.size() / 3);
  float voxel = 0.0f;
  double voxels = 0.0;
  bool small = false;
  for (double cells = 16.0; cells >= 1.0 && !small; cells = std::floor(cells / 2.0)) {
    // A float voxel, as the desc holds it: denormal or overflowing ones are fine too (0 is the
    // default 0.01, infinity is refused).
    voxel = extent > 0.0 ? static_cast<float>(extent / cells) : 1.0f;
    voxels = grid_voxels(lo, hi, voxel, padding);
    small = voxels * (triangles + 16.0) <= kMaxWork;
  }
  if (!small) return 0;

  sph_context* context = create_cpu_context();
  const uint32_t baseline = live_objects();

  sph_tools::ShapeDesc shape;
  shape.kind = sph_tools::ShapeDesc::Kind::kMesh;
  shape.path = "colliders[0].shape";
  shape.mesh_file = kName;
  shape.mesh_vertices = std::move(mesh.vertices);
  shape.mesh_indices = std::move(mesh.indices);
  sph_mesh_desc_init(&shape.mesh);
  shape.mesh.voxel_size = voxel;
  shape.mesh.band_width = band;
  shape.mesh.padding_voxels = padding;

  sph_sdf* sdf = nullptr;
  if (through_factory) {
    try {
      sdf = sph_tools::create_sdf(context, shape);
      if (!sdf) violation("create_sdf returned NULL without an error");
    } catch (const sph_tools::SceneError& e) {
      if (std::string(e.what()).empty()) violation("a SceneError without a message");
      if (e.path() != shape.path) violation("a SceneError at %s, not the shape's path", e.path().c_str());
    }
  } else {
    sph_mesh_desc d = shape.mesh;
    d.vertices = shape.mesh_vertices.data();
    d.vertex_count = static_cast<uint32_t>(shape.mesh_vertices.size() / 3);
    d.indices = shape.mesh_indices.data();
    d.index_count = static_cast<uint32_t>(shape.mesh_indices.size());
    // *out is written only on success: a failure leaves this stand-in pointer as it was.
    sph_sdf* const untouched = reinterpret_cast<sph_sdf*>(&sdf);
    sdf = untouched;
    const sph_result r = FUZZ_CALL(sph_sdf_create_from_mesh(context, &d, &sdf));
    if (r != SPH_OK) {
      if (sdf != untouched)
        violation("sph_sdf_create_from_mesh failed with %d but wrote *out", static_cast<int>(r));
      sdf = nullptr;
      // A grid within the budget is far below the library's limit: only the arguments may fail.
      if (r != SPH_ERROR_INVALID_ARGUMENT)
        violation("sph_sdf_create_from_mesh failed with %d: %s", static_cast<int>(r), sph_get_last_error());
    } else if (!sdf) {
      violation("sph_sdf_create_from_mesh succeeded without an asset");
    }
  }
  if (sdf) {
    uint32_t dims[3] = {0, 0, 0};
    FUZZ_CALL(sph_sdf_get_dims(sdf, dims));
    const double got = static_cast<double>(dims[0]) * dims[1] * dims[2];
    if (got > voxels) violation("a grid of %g voxels, estimated at most %g", got, voxels);
    // The distance is a number (of either sign) at the middle of the mesh's box and at the
    // corners of the grid's box (where the far field is farthest from the surface).
    const double v = voxel == 0.0f ? 0.01 : static_cast<double>(voxel);
    const double pad = (padding == 0 ? 4.0 : padding) * v;
    for (int corner = 0; corner < 9; ++corner) {
      float point[3];
      for (int a = 0; a < 3; ++a)
        point[a] = static_cast<float>(corner == 8         ? lo[a] / 2.0 + hi[a] / 2.0
                                      : (corner >> a) & 1 ? hi[a] + pad
                                                          : lo[a] - pad);
      if (!std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2])) continue;
      float distance = 0.0f;
      if (FUZZ_CALL(sph_sdf_sample(sdf, sph_vec3{point[0], point[1], point[2]}, &distance)) != SPH_OK)
        violation("cannot sample the asset");
      if (std::isnan(distance))
        violation("the asset's distance at (%g, %g, %g) is NaN", point[0], point[1], point[2]);
    }
    if (FUZZ_CALL(sph_sdf_destroy(sdf)) != SPH_OK) violation("cannot destroy the asset");
  }
  if (live_objects() != baseline) violation("%u library objects leaked", live_objects() - baseline);
  if (FUZZ_CALL(sph_context_destroy(context)) != SPH_OK) violation("the context is still busy");
  return 0;
}
