// Everything the per-particle physics needs, passed by value to every kernel and loop
// (no globals: two worlds in one process, even on two devices, keep their own).
#pragma once

#include "equation_of_state.h"
#include "kernels.h"
#include "vec3.h"

namespace sph {

struct FluidConstants {
  KernelCoefficients kernel;
  float particle_mass;  // kg
  // The density's self term, 1/m^3: rho_i = m (density_self_weight + sum_{j != i} W_spiky(r_ij))
  // (density.h); set so that the FCC lattice at the world's spacing has rest density.
  float density_self_weight;
  float rest_density;  // rho0, kg/m^3
  EosConstants eos;
  float viscosity;  // mu of Mueller's viscosity
  Vec3 gravity;     // m/s^2
  // Surface tension (Morris/Mueller colour field), used when the feature is on.
  float surface_tension;      // sigma, N/m
  float surface_threshold;    // |grad c| above which the surface stress acts, 1/m
  float surface_delta_scale;  // the capillary stress's share of sigma / the flat lattice
                              // surface's sampled delta integral (CSF)
  float surface_cohesion;     // gamma m 32 / (pi h^9) of the cohesion, set from its share of
                              // sigma (surface_tension_cohesion.h), 1/(m^5 s^2)
  // Clavet radial impulses, used when that viscosity method is chosen.
  float clavet_linear;     // sigma, 1/s
  float clavet_quadratic;  // beta, 1/m
  float dt;                // the substep's length (impulse-based terms need it)
};

}  // namespace sph
