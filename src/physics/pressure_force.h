// SPDX-License-Identifier: MIT
// The pressure force: Monaghan's symmetric form a_i = -sum_j m (p_i / rho_i^2 + p_j / rho_j^2)
// grad W_spiky(x_i - x_j) (Monaghan 1992), not the thesis's eq. 14 (Mueller 2003),
// -sum_j m (p_i + p_j) / (2 rho_j) grad W_ij / rho_i. Both are antisymmetric in i and j
// (momentum is conserved), but in a full neighbourhood sum_j (m / rho_j) grad W_ij vanishes, so
// eq. 14's p_i half drops out and it yields only grad p / 2: a tank at rest then holds twice the
// hydrostatic pressure and the fluid's sound speed is sqrt(k / 2), not the sqrt(k) the step
// limits assume (tests/validation, hydrostatic tank; docs/physics.md). Monaghan's form gives
// grad p, and with summation density it is the form whose work is exactly the change of the
// equation of state's internal energy, so the total energy of a closed box only falls (by
// viscosity and collisions). Every world runs it; its stability ceiling is the acoustic one of
// the world's equation of state (methods.h).
#pragma once

#include "fluid_base.h"
#include "force_pair.h"
#include "host_device.h"

namespace sph {

struct SymmetricPressure {
  static constexpr const char* kName = "pressure";

  template <class T>
  struct SumsOf {
    Vec3Of<T> pressure;      // sum -(p_j / rho_j^2) grad W_spiky
    Vec3Of<T> own_pressure;  // sum -p_i grad W_spiky (times 1 / rho_i^2 in acceleration())
  };
  using Sums = SumsOf<float>;
  template <class T = float>
  SPH_HD static SumsOf<T> zero_sums() {
    const T zero(0);
    return SumsOf<T>{{zero, zero, zero}, {zero, zero, zero}};
  }

  template <class T>
  SPH_HD static void add_pair(const FluidBase& f, const ForceParticleOf<T>& i, const ForcePairOf<T>& j,
                              SumsOf<T>& s) {
    // -(p_i / rho_i^2 + p_j / rho_j^2) grad W_spiky; m and 1 / rho_i^2 are applied once below.
    const Vec3Of<T> grad = spiky_gradient(f.kernel, j.d, j.r);
    s.pressure += j.only(grad * (-j.pressure * j.inv_density * j.inv_density));
    s.own_pressure += j.only(grad * (-i.pressure));
  }

  // The pressure acceleration, the first part of a_i.
  SPH_HD static Vec3 acceleration(const FluidBase& f, const ForceParticle& i, const Sums& s) {
    return (s.pressure + s.own_pressure * (i.inv_density * i.inv_density)) * f.particle_mass;
  }

  // The explicit scheme's acoustic limit, which holds whatever dt_max and lambda are:
  // dt <= 0.4 h / c. A pressure wave must not cross more than a fraction of a kernel radius per
  // step; measured on a dam break (tests/extremes), fixed steps of 1 h/c stay bounded and
  // 2 h/c blow up (energy x1000), so 0.4 leaves a margin of 2.5. 0 (no ceiling) when c is 0.
  static constexpr float kStabilityFactor = 0.4f;
  SPH_HD static float stability_ceiling(float kernel_radius, float sound_speed) {
    return sound_speed > 0.0f ? kStabilityFactor * kernel_radius / sound_speed : 0.0f;
  }
};

}  // namespace sph
