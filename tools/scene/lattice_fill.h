// SPDX-License-Identifier: MIT
// The particles a fluid body adds, as arrays: what sph_world_fill_box, sph_world_fill_sphere or
// sph_world_spawn would put into an undivided world, for a world that takes particles only as
// arrays (a distributed world refuses the fills: sph_mpi_world_add_particles).
#ifndef SPH_TOOLS_LATTICE_FILL_H
#define SPH_TOOLS_LATTICE_FILL_H

#include <vector>

#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

// Fills `fluid` into a scratch undivided world of `context` made from `def` (the fills depend
// on the def's particle spacing alone, not on other particles or colliders) and copies its
// particles out in id order, which is the order the fill numbered them: positions and
// velocities, 3 floats each. Returns the library's code (SPH_ERROR_CAPACITY when the body does
// not fit in the def's capacity); the arrays are filled only on success.
sph_result lattice_fill(sph_context* context, const sph_world_def& def, const FluidDesc& fluid,
                        std::vector<float>* positions, std::vector<float>* velocities);

}  // namespace sph_tools

#endif
