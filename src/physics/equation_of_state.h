// Equations of state: pressure from density. The thesis's modified ideal-gas law (eq. 15,
// Desbrun & Cani) and Tait's law (gamma = 7) from a chosen speed of sound.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "vec3.h"

namespace sph {

enum class EquationOfState : uint32_t { IdealGas = 0, Tait = 1 };

struct EosConstants {
  EquationOfState kind;
  float rest_density;  // rho0
  float stiffness;     // ideal gas: k of p = k (rho - rho0)
  float tait_b;        // Tait: B = rho0 c^2 / gamma
};

// Both laws are clamped at zero below rest density. Particles at a free surface miss
// neighbours, so their summed density is low; an unclamped law turns that deficit into a
// strong tension that pulls surface particles into clumps and flings them off (the tensile
// instability). Clamping is the usual weakly-compressible SPH treatment: the fluid resists
// compression and the free surface is left alone (cohesion belongs to surface tension).
SPH_HD float pressure_from_density(const EosConstants& e, float density) {
  const float excess = density - e.rest_density;
  if (excess <= 0.0f) return 0.0f;
  if (e.kind == EquationOfState::Tait) {
    const float r = density / e.rest_density;
    const float r2 = r * r;
    const float r4 = r2 * r2;
    return e.tait_b * (r4 * r2 * r - 1.0f);
  }
  return e.stiffness * excess;
}

// The numerical speed of sound of the law at rest density (for the acoustic step limit).
SPH_HD float speed_of_sound(const EosConstants& e) {
  const float c2 = e.kind == EquationOfState::Tait ? 7.0f * e.tait_b / e.rest_density : e.stiffness;
  return c2 > 0.0f ? SPH_SQRTF(c2) : 0.0f;
}

}  // namespace sph
