// Equation of state: pressure from density (thesis eq. 15).
#pragma once

#include "host_device.h"

namespace sph {

// p = k (rho - rho0); negative below rest density, which holds a free surface together.
SPH_HD float pressure_from_density(float density, float rest_density, float stiffness) {
  return stiffness * (density - rest_density);
}

}  // namespace sph
