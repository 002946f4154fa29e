// Equations of state: pressure from density, by the world's choice of the two EOS methods
// (eos_ideal_gas.h, eos_tait.h). The choice is made at run time, per density evaluation: a
// branch on a value every thread shares, cheaper than another template dimension.
#pragma once

#include <stdint.h>

#include "eos_ideal_gas.h"
#include "eos_tait.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

enum class EquationOfState : uint32_t { IdealGas = 0, Tait = 1 };

struct EosConstants {
  EquationOfState kind;
  float rest_density;  // rho0
  IdealGasEos::Constants ideal_gas;
  TaitEos::Constants tait;
};

// Both laws are clamped at zero below rest density. Particles at a free surface miss
// neighbours, so their summed density is low; an unclamped law turns that deficit into a
// strong tension that pulls surface particles into clumps and flings them off (the tensile
// instability). Clamping is the usual weakly-compressible SPH treatment: the fluid resists
// compression and the free surface is left alone (cohesion belongs to surface tension).
SPH_HD float pressure_from_density(const EosConstants& e, float density) {
  const float excess = density - e.rest_density;
  if (excess <= 0.0f) return 0.0f;
  if (e.kind == EquationOfState::Tait) return TaitEos::pressure(e.tait, density, e.rest_density);
  return IdealGasEos::pressure(e.ideal_gas, excess);
}

// The numerical speed of sound of the law at rest density (for the acoustic step limit).
SPH_HD float speed_of_sound(const EosConstants& e) {
  const float c2 = e.kind == EquationOfState::Tait ? TaitEos::squared_sound_speed(e.tait, e.rest_density)
                                                   : IdealGasEos::squared_sound_speed(e.ideal_gas);
  return c2 > 0.0f ? SPH_SQRTF(c2) : 0.0f;
}

}  // namespace sph
