// SPDX-License-Identifier: MIT
// VDB points frames through OpenVDB's point data grids.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <mutex>
#include <stdexcept>
#include <vector>

#include "vdb_file.h"
#include "writers.h"

namespace sph_tools {

namespace {

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

template <typename T>
void add_attribute(openvdb::points::PointDataGrid& grid, const openvdb::tools::PointIndexGrid& index,
                   const char* name, const std::vector<T>& values) {
  openvdb::points::appendAttribute<T>(grid.tree(), name);
  const openvdb::points::PointAttributeVector<T> wrapper(values);
  openvdb::points::populateAttribute<openvdb::points::PointDataTree, openvdb::tools::PointIndexTree,
                                     openvdb::points::PointAttributeVector<T>>(grid.tree(), index.tree(),
                                                                               name, wrapper);
}

}  // namespace

void write_vdb_points(const ParticleFrame& f, const std::string& path) {
  initialize_openvdb();
  std::vector<openvdb::Vec3f> positions(f.count), velocities(f.count);
  std::vector<float> density(f.density.begin(), f.density.end());
  std::vector<int64_t> ids(f.count);
  for (size_t i = 0; i < f.count; ++i) {
    positions[i] = openvdb::Vec3f(f.position[3 * i], f.position[3 * i + 1], f.position[3 * i + 2]);
    velocities[i] = openvdb::Vec3f(f.velocity[3 * i], f.velocity[3 * i + 1], f.velocity[3 * i + 2]);
    ids[i] = f.id[i];
  }
  // Voxels of two particle spacings hold about 11 particles each on the FCC lattice.
  const double voxel = 2.0 * (f.particle_spacing > 0.0f ? f.particle_spacing : 0.02f);
  const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
  const openvdb::points::PointAttributeVector<openvdb::Vec3f> position_wrapper(positions);
  const openvdb::tools::PointIndexGrid::Ptr index =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(position_wrapper, *transform);
  const openvdb::points::PointDataGrid::Ptr grid =
      openvdb::points::createPointDataGrid<openvdb::points::NullCodec, openvdb::points::PointDataGrid>(
          *index, position_wrapper, *transform);
  add_attribute(*grid, *index, "v", velocities);
  add_attribute(*grid, *index, "density", density);
  add_attribute(*grid, *index, "id", ids);
  grid->setName("points");
  grid->insertMeta("frame", openvdb::Int32Metadata(static_cast<int32_t>(f.frame)));
  grid->insertMeta("time", openvdb::DoubleMetadata(f.time));
  grid->insertMeta("particle_spacing", openvdb::FloatMetadata(f.particle_spacing));
  write_vdb_file(path, openvdb::GridCPtrVec{grid});
}

}  // namespace sph_tools
