// SPDX-License-Identifier: MIT
// The part of the per-particle constants that every method reads: the kernel, the particle
// mass, rest density, gravity and the substep's length. FluidConstants (fluid_constants.h)
// adds each method's own constants; a method's terms take this part and their own.
#pragma once

#include "kernels.h"
#include "vec3.h"

namespace sph {

struct FluidBase {
  KernelCoefficients kernel;  // W_spiky's coefficients scaled by the world's lattice factor
  float particle_mass;        // kg
  // The density's self term, 1/m^3: rho_i = m (density_self_weight + sum_{j != i} W_spiky(r_ij))
  // (density.h); set so that the FCC lattice at the world's spacing has rest density.
  float density_self_weight;
  float rest_density;  // rho0, kg/m^3
  Vec3 gravity;        // m/s^2
  float dt;            // the substep's length (impulse-based terms need it); set per substep
};

}  // namespace sph
