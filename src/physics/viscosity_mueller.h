// SPDX-License-Identifier: MIT
// Mueller's viscosity (thesis eq. 17): a_i = (mu / rho_i) sum_j m (v_j - v_i) / rho_j
// lap W_viscosity(|x_i - x_j|), a numerical viscosity whose coefficient is
// sph_world_params.viscosity. The default viscosity method.
#pragma once

#include "fluid_base.h"
#include "force_pair.h"
#include "host_device.h"
#include "param_table.h"
#include "world_shape.h"

namespace sph {

struct MuellerViscosity {
  static constexpr const char* kName = "mueller";

  struct Params {
    float viscosity = 1.0f;  // mu, Pa s (numerical, not water's 0.001)
  };
  static constexpr ParamField<Params> kFields[] = {
      real_field("viscosity", &Params::viscosity, at_least(0.0), ZeroMeans::Value, "Pa s"),
  };
  static bool check(const Params&, const WorldShape&, ParamConflict&) { return true; }

  struct Constants {
    float viscosity;  // mu
  };
  static Constants make_constants(const Params& p) { return Constants{p.viscosity}; }

  // The explicit diffusion limit, dt <= 0.05 h^2 / nu (kinematic viscosity nu = mu / rho0),
  // which holds whatever dt_max and lambda are: measured, 0.1 h^2 / nu is stable and 0.15
  // blows up, so 0.05 leaves a margin of 2. 0 (no ceiling) for an inviscid fluid.
  static constexpr float kStabilityFactor = 0.05f;
  static float stability_ceiling(const Params& p, const WorldShape& s) {
    const float nu = p.viscosity / s.rest_density;
    return nu > 0.0f ? kStabilityFactor * s.kernel_radius * s.kernel_radius / nu : 0.0f;
  }

  static constexpr bool kReadsNeighborCounts = false;
  static constexpr bool kReadsColourNormals = false;
  template <class T>
  struct SumsOf {
    Vec3Of<T> viscosity;  // sum (v_j - v_i) / rho_j lap W
  };
  using Sums = SumsOf<float>;
  template <class T = float>
  SPH_HD static SumsOf<T> zero_sums() {
    const T zero(0);
    return SumsOf<T>{{zero, zero, zero}};
  }
  template <class T>
  SPH_HD static void add_pair(const FluidBase& f, const Constants&, const ForceParticleOf<T>& i,
                              const ForcePairOf<T>& j, SumsOf<T>& s) {
    s.viscosity += j.only((j.v - i.v) * (viscosity_laplacian(f.kernel, j.r) * j.inv_density));
  }
  SPH_HD static void finish(const FluidBase& f, const Constants& c, const ForceParticle& i, const Sums& s,
                            Vec3& a) {
    const float m_over_rho_i = f.particle_mass * i.inv_density;
    a += s.viscosity * (c.viscosity * m_over_rho_i);
  }
};

}  // namespace sph
