// SPDX-License-Identifier: MIT
// Writes the seed corpus of fuzz_vdb (tests/fuzz/corpus/vdb/): small .vdb files made by OpenVDB,
// each behind the harness's first byte (the grid-name choice, fuzz_vdb.cpp). Run by hand when the
// seeds need remaking: fuzz_make_vdb_seeds <folder>.
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

// Writes grids to a .vdb file with the given compression, then prefixes the selector byte.
void write_seed(const std::string& path, uint8_t selector, openvdb::GridPtrVec grids, uint32_t compression) {
  const std::string tmp = path + ".tmp";
  {
    openvdb::io::File file(tmp);
    file.setCompression(compression);
    file.write(grids);
    file.close();
  }
  std::ifstream in(tmp, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream out(path, std::ios::binary);
  out.put(static_cast<char>(selector));
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::remove(tmp.c_str());
  std::printf("%s: %zu bytes\n", path.c_str(), bytes.size() + 1);
}

openvdb::FloatGrid::Ptr sphere(const char* name, float radius, float voxel, float half_width) {
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      radius, openvdb::Vec3f(0.15f, 0.15f, 0.15f), voxel, half_width);
  grid->setName(name);
  return grid;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <folder>\n", argv[0]);
    return 2;
  }
  openvdb::initialize();
  const std::string dir = argv[1];
  // 0: the first float level set (grid_name NULL), active-mask compression only.
  write_seed(dir + "/sphere_active_mask.vdb", 0, {sphere("ls", 0.08f, 0.04f, 1.5f)},
             openvdb::io::COMPRESS_ACTIVE_MASK);
  // 2: grid "ls" by name, zip and active-mask compression (OpenVDB's usual file).
  write_seed(dir + "/sphere_zip.vdb", 2, {sphere("ls", 0.08f, 0.04f, 1.5f)},
             openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
  // 3: "sphere" after a fog volume (not a level set) and a vector grid, which are skipped.
  auto fog = openvdb::FloatGrid::create(0.0f);
  fog->setName("density");
  fog->setGridClass(openvdb::GRID_FOG_VOLUME);
  fog->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
  auto vec = openvdb::Vec3SGrid::create();
  vec->setName("v");
  vec->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1.0f, 0.0f, 0.0f));
  write_seed(dir + "/three_grids.vdb", 3, {fog, vec, sphere("sphere", 0.08f, 0.04f, 1.5f)},
             openvdb::io::COMPRESS_ACTIVE_MASK);
  // 4: "density" asked for by name: a float grid that is not a level set (an error).
  write_seed(dir + "/fog_by_name.vdb", 4, {fog}, openvdb::io::COMPRESS_ACTIVE_MASK);
  // 1: a rotated, scaled transform.
  auto turned = sphere("ls", 0.08f, 0.04f, 1.5f);
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(0.04);
  xform->preRotate(0.5, openvdb::math::Y_AXIS);
  turned->setTransform(xform);
  write_seed(dir + "/rotated.vdb", 1, {turned}, openvdb::io::COMPRESS_ACTIVE_MASK);
  return 0;
}
