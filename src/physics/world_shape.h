// SPDX-License-Identifier: MIT
// What a method derives its constants from and checks its parameters against (host only): the
// world's fixed shape, and the lattice sums it may calibrate on. Core fills both (config.h and
// fcc_lattice.cpp); the physics layer only names them, so it includes nothing from core.
#pragma once

#include <stdint.h>

namespace sph {

struct WorldShape {
  float particle_spacing;  // m
  float kernel_radius;     // h, m
  float rest_density;      // rho0, kg/m^3
  float particle_mass;     // kg, from the FCC lattice at the spacing
};

// Sums over the FCC lattice at the world's spacing (core/fcc_lattice.h says what each is).
struct LatticeSums {
  double (*surface_delta_integral)(float spacing, float kernel_radius, float threshold);
  double (*cohesion_surface_energy)(float spacing, float kernel_radius);
  uint32_t (*neighbor_count)(float spacing, float kernel_radius);  // lattice points within h, self excluded
  // The boundary density's scale (1/m^3; times the particle mass, K) and its wall offset (m)
  // (fcc_boundary_calibration).
  void (*boundary_calibration)(float spacing, float kernel_radius, double* scale, double* offset);
};

}  // namespace sph
