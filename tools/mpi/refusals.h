// SPDX-License-Identifier: MIT
// What of a scene a distributed world cannot run yet, found before any world is made, so that
// every rank stops at once with the same message instead of partway through the run.
#ifndef SPH_TOOLS_REFUSALS_H
#define SPH_TOOLS_REFUSALS_H

#include <string>

#include "scene_desc.h"

namespace sph_tools {

// "" when sph-run-mpi can run the scene, else the first refused object's path and feature
// ("sources[0]: sources (emission across ranks) ..."). The world's own refusals (DFSPH, RK4,
// springs) come from sph_mpi_world_create, which names them.
std::string distributed_refusal(const SceneDesc& scene);

}  // namespace sph_tools

#endif
