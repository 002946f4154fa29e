// Internal descriptions of a world: what is fixed at creation and what can change per step.
#pragma once

#include <stdint.h>

#include "../physics/fluid_constants.h"
#include "../physics/step_control.h"
#include "../physics/vec3.h"

namespace sph {

enum class Integrator : uint32_t { SymplecticEuler = 0, Rk4 = 1 };

struct WorldConfig {
  uint32_t capacity = 0;
  uint32_t features = 0;
  Integrator integrator = Integrator::SymplecticEuler;
  float particle_spacing = 0.0f;
  float kernel_radius = 0.0f;
  float rest_density = 0.0f;
  float particle_mass = 0.0f;  // derived from the FCC lattice at creation
};

struct RuntimeParams {
  Vec3 gravity{0.0f, -9.81f, 0.0f};
  float stiffness = 100.0f;
  float viscosity = 1.0f;
  float step_factor = 0.4f;
  float dt_min = 1e-6f;
  float dt_max = 1e-3f;
  uint32_t max_substeps = 10000;
};

inline FluidConstants make_fluid_constants(const WorldConfig& c, const RuntimeParams& p) {
  FluidConstants f;
  f.kernel = make_kernel_coefficients(c.kernel_radius);
  f.particle_mass = c.particle_mass;
  f.rest_density = c.rest_density;
  f.stiffness = p.stiffness;
  f.viscosity = p.viscosity;
  f.gravity = p.gravity;
  return f;
}

inline StepLimits make_step_limits(const WorldConfig& c, const RuntimeParams& p) {
  return StepLimits{p.step_factor, c.kernel_radius, p.dt_min, p.dt_max};
}

}  // namespace sph
