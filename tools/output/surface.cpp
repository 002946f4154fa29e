// SPDX-License-Identifier: MIT
// The fluid surface: particles rasterised into a narrow-band level set with OpenVDB's
// ParticlesToLevelSet, smoothed, written as .vdb, and meshed with volumeToMesh into an OBJ
// (write_obj.cpp).
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "new_file.h"
#include "vdb_file.h"
#include "writers.h"

namespace sph_tools {

namespace {

// The particle list ParticlesToLevelSet reads: positions with one radius.
class ParticleList {
 public:
  using PosType = openvdb::Vec3R;
  ParticleList(const ParticleFrame& f, double radius) : f_(f), radius_(radius) {}
  size_t size() const { return f_.count; }
  void getPos(size_t n, openvdb::Vec3R& xyz) const {
    xyz = openvdb::Vec3R(f_.position[3 * n], f_.position[3 * n + 1], f_.position[3 * n + 2]);
  }
  void getPosRad(size_t n, openvdb::Vec3R& xyz, openvdb::Real& radius) const {
    getPos(n, xyz);
    radius = radius_;
  }

 private:
  const ParticleFrame& f_;
  double radius_;
};

}  // namespace

void write_surface(const ParticleFrame& f, float radius, float voxel, const std::string& vdb_path,
                   const std::string& obj_path, SurfaceMesh* mesh) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  const float half_width = 3.0f;
  openvdb::FloatGrid::Ptr grid = openvdb::createLevelSet<openvdb::FloatGrid>(voxel, half_width);
  if (f.count > 0) {
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
    raster.setRmin(1.0);  // in voxels; radius is at least 1.5 voxels (sph-run checks)
    raster.rasterizeSpheres(ParticleList(f, radius));
    raster.finalize(true);
    // Blobs of single spheres smoothed into a surface: a mean-value pass rounds the dimples
    // between particles; then the surface moves in to where the fluid ends, half a spacing
    // beyond the outer particles' centres (less for radii below that), so the mesh holds about
    // the fluid's volume.
    openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
    filter.mean(1);
    const float shrink = std::min(radius - 0.5f * f.particle_spacing, radius - 1.5f * voxel);
    if (shrink > 0.0f) filter.offset(shrink);
  }
  grid->setName("surface");
  grid->insertMeta("frame", openvdb::Int32Metadata(static_cast<int32_t>(f.frame)));
  grid->insertMeta("time", openvdb::DoubleMetadata(f.time));
  write_vdb_file(vdb_path, openvdb::GridCPtrVec{grid});

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  if (f.count > 0) openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0);
  mesh->vertices.resize(3 * points.size());
  for (size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) mesh->vertices[3 * i + a] = points[i][a];
  // volumeToMesh's faces wind clockwise seen from outside; the mesh (and OBJ) use the usual
  // counter-clockwise order, so each face is reversed.
  mesh->triangles.clear();
  mesh->triangles.reserve(3 * triangles.size() + 6 * quads.size());
  for (const openvdb::Vec3I& t : triangles) mesh->triangles.insert(mesh->triangles.end(), {t[2], t[1], t[0]});
  for (const openvdb::Vec4I& q : quads)
    mesh->triangles.insert(mesh->triangles.end(), {q[2], q[1], q[0], q[3], q[2], q[0]});
  write_obj(*mesh, f.frame, f.time, obj_path);
}

}  // namespace sph_tools
