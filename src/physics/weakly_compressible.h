// SPDX-License-Identifier: MIT
// The thesis's weakly compressible scheme, the default solver (sph_world_def.solver =
// SPH_SOLVER_WCSPH): the pressure from the equation of state (eos_ideal_gas.h, eos_tait.h) and
// the symmetric pressure force (pressure_force.h), integrated explicitly under the acoustic step
// ceiling. Its parameters are those of its equation of state, plus the one both laws share: the
// bounded tension (tension_ratio, sph_world_params; methods.h, pressure_from_density). It is in
// the method list so that every value of a world's solver names a method (scene files,
// checkpoints, the C API's descriptions). The other solver is DFSPH (dfsph.h), which has no
// equation of state: the tension ratio is accepted there and has no effect, like the stiffness.
#pragma once

#include "param_table.h"
#include "world_shape.h"

namespace sph {

// The largest tension ratio: the law may run down to 87.5 % of rho0. Past a few per cent a free
// surface's particles (a third to a half of their neighbours missing) all sit at the floor, and
// the floor's tension k tau rho0 then acts as a cohesion of its own; 1/8 bounds that at an eighth
// of the stiffness times rho0 (12.5 kPa at the defaults, the hydrostatic pressure 1.3 m down).
// A power of two, so that the float a caller writes at the bound is the bound the library checks
// (0.1f is above the double 0.1).
constexpr double kMaxTensionRatio = 0.125;

struct WeaklyCompressible {
  static constexpr const char* kName = "wcsph";

  struct Params {
    float tension_ratio = 0.0f;  // tau: the law holds down to (1 - tau) rho0; 0 is the clamp at rho0
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("tension_ratio", &Params::tension_ratio, within(0.0, kMaxTensionRatio), ZeroMeans::Value,
                 ""),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  // The density below which the law is held at its value: (1 - tau) rho0 (rho0 itself at tau 0,
  // exactly, so tau 0 is the clamp at zero bit for bit).
  static float tension_floor(const Params& p, const WorldShape& s) {
    return (1.0f - p.tension_ratio) * s.rest_density;
  }
};

}  // namespace sph
