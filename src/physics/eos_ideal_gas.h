// SPDX-License-Identifier: MIT
// The thesis's modified ideal-gas law (eq. 15, Desbrun & Cani): p = k (rho - rho0), held at its
// value at (1 - tau) rho0 below that density (tau = sph_world_params.tension_ratio, default 0: the
// clamp at zero; methods.h, pressure_from_density, says why). k is the squared numerical speed of
// sound. Its parameter is sph_world_params.stiffness.
#pragma once

#include "host_device.h"
#include "param_table.h"
#include "world_shape.h"

namespace sph {

struct IdealGasEos {
  static constexpr const char* kName = "ideal_gas";

  struct Params {
    float stiffness = 100.0f;  // k, m^2/s^2
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("stiffness", &Params::stiffness, above(0.0), ZeroMeans::Default, "m^2/s^2"),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float stiffness;
  };
  static Constants make_constants(const Params& p) { return Constants{p.stiffness}; }

  // excess = rho - rho0 >= -tau rho0 (negative: a tension).
  SPH_HD static float pressure(const Constants& c, float excess) { return c.stiffness * excess; }
  SPH_HD static float squared_sound_speed(const Constants& c) { return c.stiffness; }
};

}  // namespace sph
