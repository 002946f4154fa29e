// SPDX-License-Identifier: MIT
#include "vdb_bounds.h"

#ifdef SPH_TOOLS_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#include <sys/stat.h>

#include <cmath>
#include <mutex>
#include <string>

#include "vdb_read_grids.h"
#endif

namespace sph_tools {

#ifdef SPH_TOOLS_HAVE_OPENVDB
namespace {

void fill_one(ShapeDesc* shape) {
  if (shape->kind != ShapeDesc::Kind::kVdb) return;
  // Only regular files: OpenVDB would wait forever on a FIFO (building the world says why).
  struct stat st;
  if (::stat(shape->vdb_file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  try {
    // The file is read as sph_vdb_load_sdf reads it (a file cut short is an error, not a
    // runaway read); this is before the world is built, so the same file reaches the loader next.
    std::string error;
    const openvdb::GridPtrVecPtr grids = sph_io::read_vdb_grids(shape->vdb_file, &error);
    if (!grids) return;
    openvdb::FloatGrid::Ptr grid;
    for (const openvdb::GridBase::Ptr& base : *grids) {
      if (!shape->vdb_grid.empty() && base->getName() != shape->vdb_grid) continue;
      openvdb::FloatGrid::Ptr candidate = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
      if (candidate && (!shape->vdb_grid.empty() || candidate->getGridClass() == openvdb::GRID_LEVEL_SET)) {
        grid = candidate;
        break;
      }
    }
    if (!grid) return;
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (box.empty()) return;
    bool first = true;
    for (int k = 0; k < 8; ++k) {
      const openvdb::Vec3d corner((k & 1 ? box.max().x() : box.min().x()) + (k & 1 ? 0.5 : -0.5),
                                  (k & 2 ? box.max().y() : box.min().y()) + (k & 2 ? 0.5 : -0.5),
                                  (k & 4 ? box.max().z() : box.min().z()) + (k & 4 ? 0.5 : -0.5));
      const openvdb::Vec3d w = grid->indexToWorld(corner);
      const sph_vec3 p{static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
      shape->vdb_bounds_min =
          first ? p
                : sph_vec3{std::fmin(shape->vdb_bounds_min.x, p.x), std::fmin(shape->vdb_bounds_min.y, p.y),
                           std::fmin(shape->vdb_bounds_min.z, p.z)};
      shape->vdb_bounds_max =
          first ? p
                : sph_vec3{std::fmax(shape->vdb_bounds_max.x, p.x), std::fmax(shape->vdb_bounds_max.y, p.y),
                           std::fmax(shape->vdb_bounds_max.z, p.z)};
      first = false;
    }
    shape->has_vdb_bounds = true;
  } catch (const std::exception&) {
    // Unreadable (OpenVDB's exceptions, or an allocation a damaged file asked for): building
    // the world says why.
  }
}

}  // namespace

void fill_vdb_bounds(SceneDesc* scene) {
  for (ColliderDesc& c : scene->colliders) fill_one(&c.shape);
  for (SourceDesc& s : scene->sources) fill_one(&s.shape);
  for (SinkDesc& s : scene->sinks) fill_one(&s.shape);
  for (ForceFieldDesc& f : scene->force_fields)
    if (f.has_region) fill_one(&f.region);
}
#else
void fill_vdb_bounds(SceneDesc*) {}
#endif

}  // namespace sph_tools
