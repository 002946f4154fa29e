// SPDX-License-Identifier: MIT
// A level set written with OpenVDB loads back through sph_vdb_load_sdf with the same
// distances (issue 4, item 6): at every voxel centre of the narrow band the asset returns the
// file's value to float round-off, and between voxels it agrees with OpenVDB's own trilinear
// sampler. Also the loader's errors.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

#include "sph_vdb.h"
#include "support.h"

namespace {

std::string temp_path(const char* name) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && dir[0] ? dir : "/tmp") + "/sph_test_" + std::to_string(::getpid()) + "_" + name;
}

openvdb::FloatGrid::Ptr write_sphere(const std::string& path) {
  openvdb::initialize();
  // Radius 0.1 m at (0.3, -0.2, 0.05), 5 mm voxels, a rotated-and-scaled transform is not
  // needed: the VDB convention (voxel centres at integer indices) is what is under test.
  openvdb::FloatGrid::Ptr grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      0.1f, openvdb::Vec3f(0.3f, -0.2f, 0.05f), 0.005f, 3.0f);
  grid->setName("sphere");
  openvdb::io::File file(path);
  openvdb::GridPtrVec grids{grid};
  file.write(grids);
  file.close();
  return grid;
}

void test_level_set_round_trip(void**) {
  const std::string path = temp_path("sphere.vdb");
  openvdb::FloatGrid::Ptr grid = write_sphere(path);
  sph_context* context = nullptr;
  assert_int_equal(sph_test_context_create(&context), SPH_OK);
  sph_sdf* sdf = nullptr;
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_OK);
  assert_non_null(sdf);

  // Voxel centres: exact values (the asset stores the file's floats).
  openvdb::FloatGrid::ConstAccessor access = grid->getConstAccessor();
  int checked = 0;
  for (auto it = grid->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3d w = grid->indexToWorld(it.getCoord());
    float d = 0.0f;
    const sph_vec3 p{static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
    assert_int_equal(sph_sdf_sample(sdf, p, &d), SPH_OK);
    // Positions are rounded to float and the index is recovered through the inverse affine
    // map: 1e-6 m of position error moves the sample by at most that much.
    assert_true(std::fabs(d - *it) <= 2e-6f);
    ++checked;
  }
  assert_true(checked > 1000);

  // Between voxels: OpenVDB's trilinear sampler in world space, at points inside the band.
  openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*grid);
  for (int k = 0; k < 200; ++k) {
    const double angle = 0.7 * k, z = std::cos(1.3 * k) * 0.08;
    const double r = 0.1 + 0.004 * std::sin(0.37 * k);
    const openvdb::Vec3d w(0.3 + r * std::cos(angle) * std::sqrt(1 - z * z / 0.01),
                           -0.2 + r * std::sin(angle) * std::sqrt(1 - z * z / 0.01), 0.05 + z);
    const float expected = sampler.wsSample(w);
    float d = 0.0f;
    const sph_vec3 p{static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
    assert_int_equal(sph_sdf_sample(sdf, p, &d), SPH_OK);
    assert_true(std::fabs(d - expected) <= 1e-5f);
    // And it is a distance to the sphere (within the level set's own discretisation, a tenth
    // of a voxel).
    assert_true(std::fabs(d - static_cast<float>((w - openvdb::Vec3d(0.3, -0.2, 0.05)).length() - 0.1)) <
                5e-4f);
  }
  // Deeper inside than the band (3 voxels, 0.015 m), as the header says: the background, flat.
  for (const float depth : {0.03f, 0.06f, 0.1f}) {
    float d = 0.0f;
    assert_int_equal(sph_sdf_sample(sdf, sph_vec3{0.3f, -0.2f + (0.1f - depth), 0.05f}, &d), SPH_OK);
    assert_float_equal(d, -grid->background(), 1e-7f);
  }
  assert_int_equal(sph_sdf_destroy(sdf), SPH_OK);
  assert_int_equal(sph_context_destroy(context), SPH_OK);
  std::remove(path.c_str());
}

void test_loader_errors(void**) {
  const std::string path = temp_path("errors.vdb");
  write_sphere(path);
  sph_context* context = nullptr;
  assert_int_equal(sph_test_context_create(&context), SPH_OK);
  sph_sdf* sdf = nullptr;
  assert_int_equal(sph_vdb_load_sdf(context, "/nonexistent/file.vdb", nullptr, &sdf),
                   SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(std::strstr(sph_vdb_get_last_error(), "path"));
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), "no_such_grid", &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(std::strstr(sph_vdb_get_last_error(), "no_such_grid"));
  assert_int_equal(sph_vdb_load_sdf(context, nullptr, nullptr, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_int_equal(sph_vdb_load_sdf(nullptr, path.c_str(), nullptr, &sdf), SPH_ERROR_INVALID_HANDLE);
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, nullptr), SPH_ERROR_INVALID_ARGUMENT);
  assert_null(sdf);
  // A file that is not a VDB file.
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fputs("not a vdb file", f);
  std::fclose(f);
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_null(sdf);
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), "sphere", &sdf), SPH_ERROR_INVALID_ARGUMENT);
  // A fog volume alone: the message says what the file holds.
  openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
  fog->setGridClass(openvdb::GRID_FOG_VOLUME);
  fog->setName("density");
  {
    openvdb::io::File file(path);
    file.write(openvdb::GridPtrVec{fog});
  }
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(
      std::strstr(sph_vdb_get_last_error(), "no float level set (it holds 'density' (float, fog volume))"));
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), "sphere", &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(std::strstr(sph_vdb_get_last_error(), "no grid named 'sphere' (it holds 'density'"));
  // Two voxels 2000 apart: a dense grid of 2003^3 voxels, over 2^31, counted in whole voxels.
  openvdb::FloatGrid::Ptr far = openvdb::FloatGrid::create(0.3f);
  far->setGridClass(openvdb::GRID_LEVEL_SET);
  far->tree().setValue(openvdb::Coord(0, 0, 0), -0.1f);
  far->tree().setValue(openvdb::Coord(2000, 2000, 2000), 0.1f);
  {
    openvdb::io::File file(path);
    file.write(openvdb::GridPtrVec{far});
  }
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_ERROR_CAPACITY);
  assert_non_null(std::strstr(sph_vdb_get_last_error(), "would have 8036054027 voxels (over 2^31)"));
  assert_null(sdf);
  // A non-finite distance is named by the file's voxel and its world position.
  openvdb::FloatGrid::Ptr bad = write_sphere(path);
  bad->tree().setValueOn(openvdb::Coord(80, -40, 10), std::numeric_limits<float>::quiet_NaN());
  {
    openvdb::io::File file(path);
    file.write(openvdb::GridPtrVec{bad});
  }
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(std::strstr(sph_vdb_get_last_error(),
                              "value at voxel (80, -40, 10) at (0.4, -0.2, 0.05) is not finite"));
  assert_null(sdf);
  // A level set with no active voxels (sph-run's surface of a frame without particles).
  openvdb::FloatGrid::Ptr empty = openvdb::FloatGrid::create(0.03f);
  empty->setGridClass(openvdb::GRID_LEVEL_SET);
  empty->setName("surface");
  openvdb::io::File file(path);
  file.write(openvdb::GridPtrVec{empty});
  file.close();
  assert_int_equal(sph_vdb_load_sdf(context, path.c_str(), nullptr, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(std::strstr(sph_vdb_get_last_error(), "no active voxels"));
  assert_null(sdf);
  assert_int_equal(sph_context_destroy(context), SPH_OK);
  std::remove(path.c_str());
}

// A file cut short anywhere (a copy interrupted, a cache still being written) is refused with
// one clear message and no asset. io::File went on past the end with the offsets and lengths it
// had failed to read: 91 bytes of this sphere (the end of the grid's type name) made it allocate
// gigabytes without end.
void test_truncated_files(void**) {
  const std::string path = temp_path("whole.vdb"), cut = temp_path("cut.vdb");
  write_sphere(path);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  assert_non_null(f);
  std::string bytes;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) bytes.append(buffer, n);
  std::fclose(f);
  assert_true(bytes.size() > 1000);

  sph_context* context = nullptr;
  assert_int_equal(sph_test_context_create(&context), SPH_OK);
  int cuts = 0;
  // Every length through the header and the grid's descriptor, then every 97th.
  for (size_t length = 0; length < bytes.size(); length += length < 400 ? 1 : 97) {
    std::FILE* o = std::fopen(cut.c_str(), "wb");
    assert_non_null(o);
    assert_int_equal(std::fwrite(bytes.data(), 1, length, o), length);
    std::fclose(o);
    sph_sdf* sdf = nullptr;
    const sph_result r = sph_vdb_load_sdf(context, cut.c_str(), nullptr, &sdf);
    if (r != SPH_ERROR_INVALID_ARGUMENT || !std::strstr(sph_vdb_get_last_error(), "ends early"))
      fail_msg("%zu of %zu bytes: result %d, \"%s\"", length, bytes.size(), static_cast<int>(r),
               sph_vdb_get_last_error());
    assert_null(sdf);
    ++cuts;
  }
  assert_true(cuts > 700);
  // The whole file still loads.
  std::FILE* o = std::fopen(cut.c_str(), "wb");
  assert_int_equal(std::fwrite(bytes.data(), 1, bytes.size(), o), bytes.size());
  std::fclose(o);
  sph_sdf* sdf = nullptr;
  assert_int_equal(sph_vdb_load_sdf(context, cut.c_str(), nullptr, &sdf), SPH_OK);
  assert_int_equal(sph_sdf_destroy(sdf), SPH_OK);
  assert_int_equal(sph_context_destroy(context), SPH_OK);
  std::remove(path.c_str());
  std::remove(cut.c_str());
}

}  // namespace

int main() {
  const CMUnitTest tests[] = {
      cmocka_unit_test(test_level_set_round_trip),
      cmocka_unit_test(test_loader_errors),
      cmocka_unit_test(test_truncated_files),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
