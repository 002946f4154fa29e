// SPDX-License-Identifier: MIT
// Internal descriptions of a world: what is fixed at creation and what can change per step,
// and the per-frame constants both derive (the physics layer's method list composes them).
#pragma once

#include <stdint.h>

#include <type_traits>

#include "../physics/fluid_constants.h"
#include "../physics/methods.h"
#include "../physics/step_control.h"
#include "../physics/vec3.h"
#include "fcc_lattice.h"

namespace sph {

enum class Integrator : uint32_t { SymplecticEuler = 0, Rk4 = 1 };

// The hard limit of a world's particle count. Particle indices are uint32 everywhere, the
// CUDA backend's sort and scans take int counts, and the radix sort's scratch (four uint32
// arrays of capacity each) lives in one Float4 array of capacity: 2^30 keeps every index,
// every capacity * 4 and every block count inside 32 bits with room to spare.
constexpr uint32_t kMaxWorldCapacity = 1u << 30;

struct WorldConfig {
  // Particles the backend has room for now; grows (World::reserve_particles) up to
  // max_capacity, never past it, and never shrinks.
  uint32_t capacity = 0;
  uint32_t max_capacity = 0;  // resolved: >= capacity, <= kMaxWorldCapacity
  uint32_t features = 0;
  Integrator integrator = Integrator::SymplecticEuler;
  ViscosityMethod viscosity_method = ViscosityMethod::Mueller;
  EquationOfState equation_of_state = EquationOfState::IdealGas;
  Solver solver = Solver::WeaklyCompressible;
  float particle_spacing = 0.0f;
  float kernel_radius = 0.0f;
  float rest_density = 0.0f;
  float particle_mass = 0.0f;  // derived from the FCC lattice at creation
  // The density's self term (FluidConstants::density_self_weight), derived with the mass at
  // creation and when a checkpoint is loaded (it is not stored).
  float density_self_weight = 0.0f;
  // The lattice normalisation of W_spiky (fcc_spiky_scale), derived like density_self_weight.
  float spiky_scale = 1.0f;

  MethodSelection selection() const {
    return MethodSelection{features, viscosity_method, equation_of_state, solver};
  }
  WorldShape shape() const {
    return WorldShape{particle_spacing, kernel_radius, rest_density, particle_mass};
  }
};

// The runtime parameters: the world's stepping and every method's (methods.h), each with its
// defaults as member initialisers and its ranges in its table.
struct RuntimeParams {
  Stepping::Params stepping;
  MethodParams methods;
};

// Calls visit(Tag<Method>{}, params) for the world's stepping, then every method with
// parameters in the method list's order (the order of checkpoints).
template <class Params, class Visit>  // Params: RuntimeParams or const RuntimeParams
void for_each_params(Params& p, Visit&& visit) {
  visit(Tag<Stepping>{}, p.stepping);
  for_each_method_params(p.methods, visit);
}

// One method's Params inside the runtime parameters.
template <class Method, class Params>  // Params: RuntimeParams or const RuntimeParams
auto& params_of(Params& p) {
  using Target = std::conditional_t<std::is_const<Params>::value, const typename Method::Params,
                                    typename Method::Params>;
  Target* found = nullptr;
  for_each_params(p, [&found](auto tag, auto& params) {
    if constexpr (std::is_same<decltype(tag), Tag<Method>>::value) found = &params;
  });
  return *found;
}

// The lattice sums of fcc_lattice.h, for the methods that calibrate on them.
inline LatticeSums fcc_lattice_sums() {
  return LatticeSums{&fcc_surface_delta_integral,
                     [](float spacing, float h) { return fcc_cohesion_lattice(spacing, h).surface_energy; },
                     &fcc_neighbor_count,
                     [](float spacing, float h, double* scale, double* offset) {
                       const BoundaryCalibration c = fcc_boundary_calibration(spacing, h);
                       *scale = c.scale;
                       *offset = c.offset;
                     }};
}

inline FluidConstants make_fluid_constants(const WorldConfig& c, const RuntimeParams& p) {
  FluidConstants f;
  f.kernel = make_kernel_coefficients(c.kernel_radius);
  f.kernel.spiky *= c.spiky_scale;
  f.kernel.spiky_grad *= c.spiky_scale;
  f.particle_mass = c.particle_mass;
  f.density_self_weight = c.density_self_weight;
  f.rest_density = c.rest_density;
  f.gravity = p.stepping.gravity;
  f.dt = 0.0f;  // set by the backend for each substep
  f.methods = make_method_constants(p.methods, c.selection(), c.shape(), fcc_lattice_sums(), f.gravity);
  return f;
}

inline StepLimits make_step_limits(const WorldConfig& c, const RuntimeParams& p) {
  StepLimits s;
  s.step_factor = p.stepping.step_factor;
  s.kernel_radius = c.kernel_radius;
  s.dt_min = p.stepping.dt_min;
  s.dt_max = p.stepping.dt_max;
  s.sound_speed = 0.0f;
  // DFSPH has no equation of state and no sound speed: its step is the CFL number alone.
  if ((p.stepping.step_limits & kStepLimitAcoustic) && c.solver == Solver::WeaklyCompressible)
    s.sound_speed = speed_of_sound(make_eos_constants(p.methods, c.selection(), c.shape()));
  s.use_force_limit = (p.stepping.step_limits & kStepLimitForce) ? 1u : 0u;
  s.stability_dt = method_stability_ceiling(p.methods, c.selection(), c.shape());
  // DFSPH's depth limit (step_control.h). Not the weakly compressible scheme's: its acoustic
  // limit (a sound speed of 10 u_ff or more) is already far shorter than sqrt(|g| H) allows.
  const Vec3 g = p.stepping.gravity;
  const float g_magnitude = length(g);
  const Dfsph::Params& dfsph = params_of<Dfsph>(p);
  const bool depth_on = c.solver == Solver::Dfsph && !(dfsph.flags & kDfsphNoDepthStepLimit) &&
                        g_magnitude > 0.0f && g_magnitude < INFINITY;
  s.depth_step_factor = depth_on ? dfsph.depth_step_factor : 0.0f;
  s.gravity_magnitude = depth_on ? g_magnitude : 0.0f;
  s.down = depth_on ? Vec3{g.x / g_magnitude, g.y / g_magnitude, g.z / g_magnitude} : Vec3{0.0f, 0.0f, 0.0f};
  return s;
}

}  // namespace sph
