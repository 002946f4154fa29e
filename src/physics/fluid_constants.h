// Everything the per-particle physics needs, passed by value to every kernel and loop
// (no globals: two worlds in one process, even on two devices, keep their own).
#pragma once

#include "kernels.h"
#include "vec3.h"

namespace sph {

struct FluidConstants {
  KernelCoefficients kernel;
  float particle_mass;  // kg
  float rest_density;   // rho0, kg/m^3
  float stiffness;      // k of p = k (rho - rho0)
  float viscosity;      // mu of Mueller's viscosity
  Vec3 gravity;         // m/s^2
};

}  // namespace sph
