// SPDX-License-Identifier: MIT
// Loads an OpenVDB level set into a dense SDF asset through the public C API. OpenVDB stays in
// this library (libsph_vdb); libsph never sees it.
#include <openvdb/openvdb.h>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "sph_vdb.h"
#include "vdb_read_grids.h"

namespace {

thread_local char g_vdb_error[1024] = "";

sph_result fail(sph_result code, const std::string& message) {
  std::snprintf(g_vdb_error, sizeof g_vdb_error, "sph_vdb_load_sdf: %s", message.c_str());
  return code;
}

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::FloatGrid::Ptr find_level_set(const openvdb::GridPtrVecPtr& grids, const char* grid_name,
                                       std::string& error) {
  for (const openvdb::GridBase::Ptr& base : *grids) {
    if (grid_name && grid_name[0] && base->getName() != grid_name) continue;
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) {
      if (grid_name && grid_name[0]) {
        error = std::string("grid_name: grid '") + grid_name + "' is not a FloatGrid";
        return nullptr;
      }
      continue;
    }
    if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) {
      if (grid_name && grid_name[0]) {
        error = std::string("grid_name: grid '") + grid_name + "' is not a level set";
        return nullptr;
      }
      continue;
    }
    return grid;
  }
  // Say what the file holds: a distance field saved with class "unknown", a fog volume or a
  // particle file given by mistake is then plain to see.
  std::string held;
  for (const openvdb::GridBase::Ptr& base : *grids) {
    if (held.size() > 400) {
      held += ", ...";
      break;
    }
    held += std::string(held.empty() ? "" : ", ") + "'" + base->getName() + "' (" + base->valueType() + ", " +
            openvdb::GridBase::gridClassToString(base->getGridClass()) + ")";
  }
  error = grid_name && grid_name[0] ? std::string("grid_name: no grid named '") + grid_name + "'"
                                    : std::string("path: the file holds no float level set");
  error += held.empty() ? std::string(" (it holds no grids)") : " (it holds " + held + ")";
  return nullptr;
}

}  // namespace

extern "C" {

SPH_API const char* SPH_CALL sph_vdb_get_last_error(void) { return g_vdb_error; }

SPH_API sph_result SPH_CALL sph_vdb_load_sdf(sph_context* context, const char* path, const char* grid_name,
                                             sph_sdf** out) {
  g_vdb_error[0] = '\0';
  if (!context) return fail(SPH_ERROR_INVALID_HANDLE, "context: is NULL");
  if (!path) return fail(SPH_ERROR_INVALID_ARGUMENT, "path: is NULL");
  if (!out) return fail(SPH_ERROR_INVALID_ARGUMENT, "out: is NULL");
  struct stat st;
  if (::stat(path, &st) != 0)
    return fail(SPH_ERROR_INVALID_ARGUMENT,
                std::string("path: cannot open '") + path + "' (" + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode))
    return fail(SPH_ERROR_INVALID_ARGUMENT,
                std::string("path: '") + path +
                    "' is not a regular file (OpenVDB would read a FIFO or device "
                    "without end)");
  try {
    initialize_openvdb();
    std::string error;
    const openvdb::GridPtrVecPtr grids = sph_io::read_vdb_grids(path, &error);
    if (!grids) return fail(SPH_ERROR_INVALID_ARGUMENT, "path: " + error);
    openvdb::FloatGrid::Ptr grid = find_level_set(grids, grid_name, error);
    if (!grid) return fail(SPH_ERROR_INVALID_ARGUMENT, error);
    if (!grid->transform().isLinear())
      return fail(SPH_ERROR_INVALID_ARGUMENT,
                  "the grid's transform is not linear (frustum maps are unsupported)");

    openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (box.empty()) return fail(SPH_ERROR_INVALID_ARGUMENT, "the level set has no active voxels");
    // The dense grid spans the active box and one voxel around it. A file's active voxels may sit
    // at the 32-bit coordinate limits, where the box's own arithmetic (expand, dim) would overflow
    // (found by fuzz_vdb: a box 2^32 wide gave a negative voxel count), so the extents are checked
    // in 64 bits first.
    double voxels = 1.0;
    for (int a = 0; a < 3; ++a) {
      const int64_t lo = box.min()[a], hi = box.max()[a];
      if (lo <= static_cast<int64_t>(INT32_MIN) + 1 || hi >= static_cast<int64_t>(INT32_MAX) - 1)
        return fail(SPH_ERROR_INVALID_ARGUMENT,
                    "the level set's active voxels reach the 32-bit index limits (from " +
                        std::to_string(lo) + " to " + std::to_string(hi) + ")");
      voxels *= static_cast<double>(hi - lo + 3);
    }
    box.expand(1);
    const openvdb::Coord dim = box.dim();
    if (voxels > 2147483648.0)
      return fail(SPH_ERROR_CAPACITY, "the dense grid would have " +
                                          std::to_string(static_cast<uint64_t>(voxels)) +
                                          " voxels (over 2^31)");

    std::vector<float> dense(static_cast<size_t>(voxels));
    openvdb::FloatGrid::ConstAccessor access = grid->getConstAccessor();
    size_t at = 0;
    for (int k = 0; k < dim.z(); ++k)
      for (int j = 0; j < dim.y(); ++j)
        for (int i = 0; i < dim.x(); ++i) {
          const openvdb::Coord ijk = box.min() + openvdb::Coord(i, j, k);
          const float value = access.getValue(ijk);
          // Named here by the file's own voxel: sph_sdf_create would name an index of our copy.
          if (!std::isfinite(value)) {
            const openvdb::Vec3d w = grid->indexToWorld(ijk);
            char where[160];
            std::snprintf(where, sizeof where, "voxel (%d, %d, %d) at (%g, %g, %g)", ijk.x(), ijk.y(),
                          ijk.z(), w.x(), w.y(), w.z());
            return fail(SPH_ERROR_INVALID_ARGUMENT, "the level set's value at " + std::string(where) +
                                                        " is not finite (" + std::to_string(value) + ")");
          }
          dense[at++] = value;
        }

    // OpenVDB maps index to world with row vectors: world = (i, j, k, 1) * M. Our dense index
    // (i, j, k) is the VDB index box.min() + (i, j, k).
    const openvdb::Mat4d m = grid->transform().baseMap()->getAffineMap()->getMat4();
    sph_sdf_desc desc;
    sph_sdf_desc_init(&desc);
    desc.distance.dims[0] = static_cast<uint32_t>(dim.x());
    desc.distance.dims[1] = static_cast<uint32_t>(dim.y());
    desc.distance.dims[2] = static_cast<uint32_t>(dim.z());
    const openvdb::Vec3d origin = m.transform(box.min().asVec3d());
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) desc.distance.index_to_local[r * 4 + c] = static_cast<float>(m(c, r));
      desc.distance.index_to_local[r * 4 + 3] = static_cast<float>(origin[r]);
    }
    desc.distance.data = dense.data();
    const sph_result r = sph_sdf_create(context, &desc, out);
    if (r != SPH_OK) return fail(r, sph_get_last_error());
    return SPH_OK;
  } catch (const std::bad_alloc&) {
    return fail(SPH_ERROR_OUT_OF_HOST_MEMORY, "a host allocation failed");
  } catch (const std::exception& e) {
    return fail(SPH_ERROR_INVALID_ARGUMENT, std::string("OpenVDB: ") + e.what());
  } catch (...) {
    return fail(SPH_ERROR_INTERNAL, "unknown exception");
  }
}

}  // extern "C"
