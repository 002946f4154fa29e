// SPDX-License-Identifier: MIT
// Mesh shapes in scene files (issue 21, item 4): OBJ and STL (ASCII and binary) read to the
// same triangles, bad files reported at the shape's path with the line or triangle, and a
// scene with a mesh collider builds an asset whose inside is negative.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

#include "mesh_file.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "scene_runtime.h"
#include "sdf_factory.h"

namespace {

using sph_tools::MeshData;
using sph_tools::read_mesh_file;

std::string g_dir;

// A unit tetrahedron, outward: corners 0 (origin), 1 (x), 2 (y), 3 (z).
const float kCorners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const uint32_t kFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

std::string write_file(const std::string& name, const std::string& bytes) {
  const std::string path = g_dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string tetra_obj() {
  // Vertices, then faces in the three index forms and with a negative index.
  return "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\n"
         "f 1 3 2\nf 1/1 2/2 4/3\nf 1//1 4//1 3//1\nf 2/1/1 3/1/1 -1/1/1\n";
}

std::string tetra_ascii_stl() {
  std::string s = "solid tetra\n";
  for (const auto& f : kFaces) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (uint32_t c : f) {
      char line[96];
      std::snprintf(line, sizeof line, "   vertex %g %g %g\n", kCorners[c][0], kCorners[c][1],
                    kCorners[c][2]);
      s += line;
    }
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid tetra\n";
}

std::string tetra_binary_stl() {
  std::string s(80, ' ');
  s.replace(0, 5, "solid");  // binary files may begin with "solid" too: the size decides
  const uint32_t n = 4;
  s.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& f : kFaces) {
    const float normal[3] = {0, 0, 0};
    s.append(reinterpret_cast<const char*>(normal), 12);
    for (uint32_t c : f) s.append(reinterpret_cast<const char*>(kCorners[c]), 12);
    s.append(2, '\0');
  }
  return s;
}

// The triangles of `m` as corner coordinates, for comparing files of different layouts.
std::vector<float> corners_of(const MeshData& m) {
  std::vector<float> out;
  for (uint32_t index : m.indices)
    for (int a = 0; a < 3; ++a) out.push_back(m.vertices[3 * index + a]);
  return out;
}

void test_obj_and_stl_read_the_same_triangles(void**) {
  std::vector<float> expected;
  for (const auto& f : kFaces)
    for (uint32_t c : f)
      for (int a = 0; a < 3; ++a) expected.push_back(2.0f * kCorners[c][a]);
  const std::string files[3] = {write_file("t.obj", tetra_obj()), write_file("t.stl", tetra_ascii_stl()),
                                write_file("b.STL", tetra_binary_stl())};
  for (const std::string& file : files) {
    const MeshData m = read_mesh_file(file, 2.0f);
    assert_int_equal(m.indices.size(), 12);
    const std::vector<float> got = corners_of(m);
    assert_true(got == expected);
  }
}

void expect_read_error(const std::string& name, const std::string& bytes, const char* message) {
  const std::string path = write_file(name, bytes);
  try {
    read_mesh_file(path, 1.0f);
    fail_msg("%s: read without an error", name.c_str());
  } catch (const std::runtime_error& e) {
    if (!std::strstr(e.what(), message)) fail_msg("'%s' does not say '%s'", e.what(), message);
  }
}

void test_bad_files_say_where(void**) {
  expect_read_error("a.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n",
                    "line 3: vertex 3 is not defined before this line");
  expect_read_error("b.obj", "v 0 0\n", "line 1: a vertex needs x y z");
  expect_read_error("c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "line 4: a face needs at least three");
  expect_read_error("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", "line 4: \"x\" is not a vertex index");
  expect_read_error("e.obj", "v 0 0 0\n", "has no faces");
  expect_read_error("f.obj", "v 0 0 1e39\nv 0 0 0\nv 0 0 0\nf 1 2 3\n",
                    "line 1: a coordinate is not a finite");
  std::string truncated = tetra_binary_stl();
  truncated.resize(truncated.size() - 10);
  truncated.replace(0, 5, "xxxxx");
  expect_read_error("g.stl", truncated, "is neither binary STL");
  expect_read_error("h.stl",
                    "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n endloop\n"
                    " endfacet\nendsolid\n",
                    "facet 1: has 2 vertices, not 3");
  expect_read_error("i.ply", "ply\n", "is not a .obj or .stl file");
  try {
    read_mesh_file(g_dir + "/missing.obj", 1.0f);
    fail_msg("a missing file read without an error");
  } catch (const std::runtime_error& e) {
    assert_non_null(std::strstr(e.what(), "cannot open"));
  }
}

// A scene's mesh errors carry the shape's path; a good mesh collider builds, and its asset
// is negative inside the tetrahedron and positive outside.
void test_scene_mesh_collider(void**) {
  write_file("tetra.obj", tetra_obj());
  try {
    sph_tools::parse_scene(R"({"colliders": [{"shape": {"type": "mesh", "file": "nothing.stl"}}]})", g_dir);
    fail_msg("a missing mesh file parsed");
  } catch (const sph_tools::SceneError& e) {
    assert_string_equal(e.path().c_str(), "colliders[0].shape.file");
  }
  try {
    sph_tools::parse_scene(R"({"colliders": [{"shape": {"type": "mesh", "file": "tetra.obj", "band": 2}}]})",
                           g_dir);
    fail_msg("an unknown field parsed");
  } catch (const sph_tools::SceneError& e) {
    assert_string_equal(e.path().c_str(), "colliders[0].shape.band");
  }
  const sph_tools::SceneDesc scene = sph_tools::parse_scene(
      R"({"colliders": [{"shape": {"type": "mesh", "file": "tetra.obj", "scale": 0.2, "voxel_size": 0.01,
                                    "band_width": 2, "padding_voxels": 3}}]})",
      g_dir);
  const sph_tools::ShapeDesc& shape = scene.colliders.at(0).shape;
  assert_int_equal(shape.mesh_indices.size(), 12);
  assert_true(shape.mesh.voxel_size == 0.01f && shape.mesh.band_width == 2.0f &&
              shape.mesh.padding_voxels == 3);
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 1;
  sph_context* context = nullptr;
  assert_int_equal(sph_context_create(&def, &context), SPH_OK);
  {
    sph_tools::SceneRuntime runtime(scene, context);
    sph_sdf* sdf = sph_tools::create_sdf(context, shape);
    float inside = 0.0f, outside = 0.0f;
    assert_int_equal(sph_sdf_sample(sdf, sph_vec3{0.03f, 0.03f, 0.03f}, &inside), SPH_OK);
    assert_int_equal(sph_sdf_sample(sdf, sph_vec3{0.15f, 0.15f, 0.15f}, &outside), SPH_OK);
    // Inside: 0.03 m from the three axis faces. Outside: (0.45 - 0.2) / sqrt 3 = 0.144 m from
    // the slanted face (the far field). Both within half a voxel.
    assert_true(std::fabs(inside + 0.03f) < 0.005f);
    assert_true(std::fabs(outside - 0.25f / std::sqrt(3.0f)) < 0.005f);
    assert_int_equal(sph_sdf_destroy(sdf), SPH_OK);
  }
  assert_int_equal(sph_context_destroy(context), SPH_OK);
}

// parse_mesh reads the bytes read_mesh_file reads from the file, the same way, and names the
// caller's name in its errors.
void test_parse_mesh_without_a_file(void**) {
  const MeshData from_file = read_mesh_file(write_file("p.obj", tetra_obj()), 1.0f);
  const MeshData from_bytes = sph_tools::parse_mesh(tetra_obj(), sph_tools::MeshFormat::kObj, 1.0f, "bytes");
  assert_true(from_bytes.vertices == from_file.vertices && from_bytes.indices == from_file.indices);
  const MeshData binary =
      sph_tools::parse_mesh(tetra_binary_stl(), sph_tools::MeshFormat::kStl, 1.0f, "bytes");
  assert_true(corners_of(binary) == corners_of(from_file));
  try {
    sph_tools::parse_mesh("v 0 0\n", sph_tools::MeshFormat::kObj, 1.0f, "memory");
    fail_msg("a bad vertex parsed");
  } catch (const std::runtime_error& e) {
    assert_string_equal(e.what(), "memory: line 1: a vertex needs x y z");
  }
}

// An index beyond long long was reported as the clamped 9223372036854775807; an "endfacet" after
// a facet's "endfacet" added its triangle a second time.
void test_index_overflow_and_stray_endfacet(void**) {
  expect_read_error("j.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999/1\n",
                    "line 4: vertex 99999999999999999999999 is not defined before this line (3 are)");
  expect_read_error("k.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -99999999999999999999999\n",
                    "line 4: vertex -99999999999999999999999 is not defined");
  expect_read_error("l.stl",
                    "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n"
                    " endloop\n endfacet\n endfacet\nendsolid\n",
                    "facet 1: has 0 vertices, not 3");
}

// A scene's mesh collider from `obj` (text) with `voxel` (JSON), built into an asset; the
// SceneError's message when the library refuses it.
struct MeshBuild {
  sph_context* context = nullptr;
  sph_sdf* sdf = nullptr;
  std::string error;
  sph_tools::SceneDesc scene;
  MeshBuild(const std::string& obj, const std::string& voxel) {
    write_file("build.obj", obj);
    scene = sph_tools::parse_scene(
        R"({"colliders": [{"shape": {"type": "mesh", "file": "build.obj", "voxel_size": )" + voxel + "}}]}",
        g_dir);
    sph_context_def def;
    sph_context_def_init(&def);
    def.backend = SPH_BACKEND_CPU;
    def.cpu_worker_count = 1;
    assert_int_equal(sph_context_create(&def, &context), SPH_OK);
    try {
      sdf = sph_tools::create_sdf(context, scene.colliders.at(0).shape);
    } catch (const sph_tools::SceneError& e) {
      error = e.what();
    }
  }
  ~MeshBuild() {
    sph_sdf_destroy(sdf);
    sph_context_destroy(context);
  }
};

// Fuzz input tiny-triangle-nan-distance: a triangle far smaller than the voxels (1e-45 m at
// 0.01 m) made point_triangle_distance divide 0 by 0 from cancelling products; the voxels it
// alone reached stayed infinite and samples among them were NaN.
void test_tiny_triangle_has_finite_distances(void**) {
  MeshBuild b("v 1e-45 0 0\nv 0 1e-45 0\nv 0 0 1e-44\nf 1 2 3\n", "0.01");
  assert_non_null(b.sdf);
  uint32_t dims[3];
  assert_int_equal(sph_sdf_get_dims(b.sdf, dims), SPH_OK);
  assert_true(dims[0] == 9 && dims[1] == 9 && dims[2] == 9);
  for (int k = 0; k < 9; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i) {
        const sph_vec3 p{0.01f * (i - 4), 0.01f * (j - 4), 0.01f * (k - 4)};
        float d = NAN;
        assert_int_equal(sph_sdf_sample(b.sdf, p, &d), SPH_OK);
        // The triangle is a point at this scale: the distance is that to the origin.
        const float expected = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
        if (!(std::fabs(d - expected) < 1e-5f))
          fail_msg("distance %g at (%d, %d, %d), not %g", d, i, j, k, expected);
      }
}

// Fuzz input denormal-voxel-inverse-overflow: a voxel of 2.8e-45 m (a float denormal) inverted
// to an infinite local-to-index map, and every sample of the asset was NaN; it is refused.
void test_denormal_voxel_is_refused(void**) {
  MeshBuild b("v 5e-44 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n", "2.8e-45");
  assert_null(b.sdf);
  if (b.error.find("inverse (local to index) overflows float") == std::string::npos)
    fail_msg("'%s' does not say the voxel is too small", b.error.c_str());
}

// Fuzz input grid-wider-than-float: a mesh 3.2e38 m across (its vertices finite) had a grid whose
// distances overflowed float, and samples near its corners were NaN; it is refused.
void test_grid_wider_than_float_is_refused(void**) {
  MeshBuild b(
      "v -1.6e38 -1.6e38 -1.6e38\nv 1.6e38 -1.6e38 -1.6e38\nv -1.6e38 1.6e38 -1.6e38\n"
      "v -1.6e38 -1.6e38 1.6e38\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
      "4e37");
  assert_null(b.sdf);
  if (b.error.find("reaches past float's range") == std::string::npos)
    fail_msg("'%s' does not say the grid is too large for float", b.error.c_str());
  // A grid 1e38 m across (4 voxels of 5e36 m and the default padding of 4 each side) is fine.
  MeshBuild smaller(
      "v -1e37 -1e37 -1e37\nv 1e37 -1e37 -1e37\nv -1e37 1e37 -1e37\nv -1e37 -1e37 1e37\n"
      "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
      "5e36");
  assert_non_null(smaller.sdf);
  float d = NAN;
  assert_int_equal(sph_sdf_sample(smaller.sdf, sph_vec3{3e37f, 3e37f, 3e37f}, &d), SPH_OK);
  assert_true(std::isfinite(d) && d > 0.0f);
}

}  // namespace

int main() {
  char dir[] = "/tmp/sph_mesh_files_XXXXXX";
  if (!mkdtemp(dir)) return 1;
  g_dir = dir;
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_obj_and_stl_read_the_same_triangles),
      cmocka_unit_test(test_bad_files_say_where),
      cmocka_unit_test(test_scene_mesh_collider),
      cmocka_unit_test(test_parse_mesh_without_a_file),
      cmocka_unit_test(test_index_overflow_and_stray_endfacet),
      cmocka_unit_test(test_tiny_triangle_has_finite_distances),
      cmocka_unit_test(test_denormal_voxel_is_refused),
      cmocka_unit_test(test_grid_wider_than_float_is_refused),
  };
  const int failed = cmocka_run_group_tests(tests, nullptr, nullptr);
  if (std::system(("rm -rf '" + g_dir + "'").c_str()) != 0) std::fprintf(stderr, "cannot remove %s\n", dir);
  return failed;
}
