// SPDX-License-Identifier: MIT
// Which candidate points keep a minimum distance from a set of existing points: sources use it
// to skip lattice points where fluid already is.
#pragma once

#include <vector>

#include "../physics/vec3.h"
#include "host_memory.h"

namespace sph {

// keep[i] is 1 when no existing point lies closer than min_distance to candidates[i].
HostVector<char> clear_of_points(const HostVector<Vec3>& existing, const HostVector<Vec3>& candidates,
                                 float min_distance);

}  // namespace sph
