// SPDX-License-Identifier: MIT
// The thesis's weakly compressible scheme, the default solver (sph_world_def.solver =
// SPH_SOLVER_WCSPH): the pressure from the equation of state (eos_ideal_gas.h, eos_tait.h) and
// the symmetric pressure force (pressure_force.h), integrated explicitly under the acoustic step
// ceiling. Its parameters are those of its equation of state; it is in the method list so that
// every value of a world's solver names a method (scene files, checkpoints, the C API's
// descriptions). The other solver is DFSPH (dfsph.h).
#pragma once

namespace sph {

struct WeaklyCompressible {
  static constexpr const char* kName = "wcsph";
};

}  // namespace sph
