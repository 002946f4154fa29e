// Equation of state: pressure from density (thesis eq. 15).
#pragma once

#include "host_device.h"

namespace sph {

// p = k (rho - rho0), clamped at zero below rest density. Particles at a free surface miss
// neighbours, so their summed density is low; the unclamped form turns that deficit into a
// strong tension that pulls surface particles into clumps and flings them off (the tensile
// instability). Clamping is the usual weakly-compressible SPH treatment: the fluid resists
// compression and the free surface is left alone (cohesion belongs to surface tension).
SPH_HD float pressure_from_density(float density, float rest_density, float stiffness) {
  const float excess = density - rest_density;
  return excess > 0.0f ? stiffness * excess : 0.0f;
}

}  // namespace sph
