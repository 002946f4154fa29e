// SPDX-License-Identifier: MIT
// The extent of the level sets that scene files load from .vdb files, read with OpenVDB, for
// the preview (the C API's SDF assets do not tell their extent).
#ifndef SPH_TOOLS_VDB_BOUNDS_H
#define SPH_TOOLS_VDB_BOUNDS_H

#include "scene_desc.h"

namespace sph_tools {

// Fills has_vdb_bounds and the box of every .vdb shape in `scene` that can be read (the grid
// sph_vdb_load_sdf would take: the named one, else the first float level set). Shapes that
// cannot be read are left alone: building the world reports them. Does nothing in builds
// without OpenVDB.
void fill_vdb_bounds(SceneDesc* scene);

}  // namespace sph_tools

#endif
