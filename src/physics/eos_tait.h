// SPDX-License-Identifier: MIT
// Tait's law (gamma = 7) from a chosen speed of sound c: p = B ((rho / rho0)^7 - 1),
// B = rho0 c^2 / 7, held at its value at (1 - tau) rho0 below that density (tau =
// sph_world_params.tension_ratio, default 0: the clamp at zero; methods.h, pressure_from_density,
// says why).
#pragma once

#include "host_device.h"
#include "param_table.h"
#include "world_shape.h"

namespace sph {

struct TaitEos {
  static constexpr const char* kName = "tait";

  struct Params {
    float speed_of_sound = 10.0f;  // c, m/s
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("speed_of_sound", &Params::speed_of_sound, above(0.0), ZeroMeans::Default, "m/s"),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float b;  // B = rho0 c^2 / 7
  };
  static Constants make_constants(const Params& p, const WorldShape& s) {
    return Constants{s.rest_density * p.speed_of_sound * p.speed_of_sound / 7.0f};
  }

  // density >= (1 - tau) rest_density (below rest_density: a tension).
  SPH_HD static float pressure(const Constants& c, float density, float rest_density) {
    const float r = density / rest_density;
    const float r2 = r * r;
    const float r4 = r2 * r2;
    return c.b * (r4 * r2 * r - 1.0f);
  }
  SPH_HD static float squared_sound_speed(const Constants& c, float rest_density) {
    return 7.0f * c.b / rest_density;
  }
};

}  // namespace sph
