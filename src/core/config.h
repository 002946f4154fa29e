// Internal descriptions of a world: what is fixed at creation and what can change per step.
#pragma once

#include <stdint.h>

#include <cmath>

#include "../physics/equation_of_state.h"
#include "../physics/fluid_constants.h"
#include "../physics/forces.h"
#include "../physics/springs.h"
#include "../physics/step_control.h"
#include "../physics/vec3.h"
#include "fcc_lattice.h"

namespace sph {

enum class Integrator : uint32_t { SymplecticEuler = 0, Rk4 = 1 };

// Feature bits, equal to the SPH_FEATURE_* values of the C header.
enum FeatureBits : uint32_t {
  kFeatureSurfaceTension = 1u << 0,
  kFeatureNormalizedDensity = 1u << 1,
  kFeatureSprings = 1u << 2,
  kFeatureAll = kFeatureSurfaceTension | kFeatureNormalizedDensity | kFeatureSprings,
};

// Step-size limits beyond eq. 32, equal to the SPH_STEP_LIMIT_* values.
enum StepLimitBits : uint32_t { kStepLimitAcoustic = 1u << 0, kStepLimitForce = 1u << 1, kStepLimitAll = 3u };

struct WorldConfig {
  uint32_t capacity = 0;
  uint32_t features = 0;
  Integrator integrator = Integrator::SymplecticEuler;
  ViscosityMethod viscosity_method = ViscosityMethod::Mueller;
  EquationOfState equation_of_state = EquationOfState::IdealGas;
  float particle_spacing = 0.0f;
  float kernel_radius = 0.0f;
  float rest_density = 0.0f;
  float particle_mass = 0.0f;  // derived from the FCC lattice at creation
  // The density's self term (FluidConstants::density_self_weight), derived with the mass at
  // creation and when a checkpoint is loaded (it is not stored).
  float density_self_weight = 0.0f;
  // The lattice normalisation of W_spiky (fcc_spiky_scale), derived like density_self_weight.
  float spiky_scale = 1.0f;
};

struct RuntimeParams {
  Vec3 gravity{0.0f, -9.81f, 0.0f};
  float stiffness = 100.0f;
  float viscosity = 1.0f;
  float step_factor = 0.4f;
  float dt_min = 1e-6f;
  float dt_max = 1e-3f;
  uint32_t max_substeps = 10000;
  uint32_t step_limits = 0;  // StepLimitBits
  // Options' parameters; each is used only when its feature or method is on.
  float surface_tension = 0.0728f;  // N/m (water at 20 C)
  float surface_threshold = 0.0f;   // |grad c| above which surface tension acts, 1/m; 0 = 0.2 / h
  float clavet_linear = 10.0f;      // 1/s
  float clavet_quadratic = 0.0f;    // 1/m
  float tait_sound_speed = 10.0f;   // m/s
  // Springs (elasticity and plasticity, SPH_FEATURE_SPRINGS).
  float spring_stiffness = 1e4f;    // k, 1/s^2
  float spring_link_radius = 0.0f;  // m; 0 = 1.2 x particle spacing, at most h
  float spring_yield_ratio = 0.1f;  // gamma
  float spring_plasticity = 0.0f;   // alpha, 1/s; 0 = elastic
  float spring_damping = 0.0f;      // c, 1/s
};

// The link radius a world uses: the parameter, or 1.2 particle spacings (the FCC lattice's
// nearest neighbours only), never more than h.
inline float spring_link_radius(const WorldConfig& c, const RuntimeParams& p) {
  const float r = p.spring_link_radius > 0.0f ? p.spring_link_radius : 1.2f * c.particle_spacing;
  return r < c.kernel_radius ? r : c.kernel_radius;
}

inline SpringConstants make_spring_constants(const WorldConfig& c, const RuntimeParams& p) {
  SpringConstants s;
  s.stiffness = p.spring_stiffness;
  s.damping = p.spring_damping;
  s.yield_ratio = p.spring_yield_ratio;
  s.plasticity = p.spring_plasticity;
  const float link = spring_link_radius(c, p);
  s.link_radius_sq = link * link;
  s.kernel_radius = c.kernel_radius;
  s.inv_kernel_radius = 1.0f / c.kernel_radius;
  return s;
}

inline EosConstants make_eos(const WorldConfig& c, const RuntimeParams& p) {
  EosConstants e;
  e.kind = c.equation_of_state;
  e.rest_density = c.rest_density;
  e.stiffness = p.stiffness;
  e.tait_b = c.rest_density * p.tait_sound_speed * p.tait_sound_speed / 7.0f;
  return e;
}

// Surface tension's constants from sigma and the lattice (docs/physics.md, Surface tension):
// the cohesion carries kSurfaceCohesionShare of sigma and the capillary stress the rest; each
// share is calibrated on the flat FCC lattice at the world's spacing (the cohesion by its
// separation energy, the stress by its sampled delta integral). 15 % is measured, not derived:
// more cohesion makes the lattice stiff and plastic (a mode-2 drop oscillation overdamped at 50 %,
// its mean shape drifting at 20 %), less holds the surface less (10 %: period 9 % fast).
constexpr float kSurfaceCohesionShare = 0.15f;
inline void set_surface_tension_constants(const WorldConfig& c, FluidConstants& f) {
  const float share = kSurfaceCohesionShare;
  const double integral =
      fcc_surface_delta_integral(c.particle_spacing, c.kernel_radius, f.surface_threshold);
  f.surface_delta_scale = integral > 0.0 ? static_cast<float>((1.0 - share) / integral) : 0.0f;
  const CohesionLattice lattice = fcc_cohesion_lattice(c.particle_spacing, c.kernel_radius);
  const double h = c.kernel_radius, m = c.particle_mass;
  const double gamma_m =
      lattice.surface_energy > 0.0 ? share * f.surface_tension / (m * lattice.surface_energy) : 0.0;
  f.surface_cohesion = static_cast<float>(cohesion_coefficient(h, gamma_m));
}

inline FluidConstants make_fluid_constants(const WorldConfig& c, const RuntimeParams& p) {
  FluidConstants f;
  f.kernel = make_kernel_coefficients(c.kernel_radius);
  f.kernel.spiky *= c.spiky_scale;
  f.kernel.spiky_grad *= c.spiky_scale;
  f.particle_mass = c.particle_mass;
  f.density_self_weight = c.density_self_weight;
  f.rest_density = c.rest_density;
  f.eos = make_eos(c, p);
  f.viscosity = p.viscosity;
  f.gravity = p.gravity;
  f.surface_tension = p.surface_tension;
  const float threshold = p.surface_threshold > 0.0f ? p.surface_threshold : 0.2f / c.kernel_radius;
  f.surface_threshold = threshold;
  f.surface_delta_scale = 1.0f;
  f.surface_cohesion = 0.0f;
  if (c.features & kFeatureSurfaceTension) set_surface_tension_constants(c, f);
  f.clavet_linear = p.clavet_linear;
  f.clavet_quadratic = p.clavet_quadratic;
  f.dt = 0.0f;  // set by the backend for each substep
  return f;
}

inline StepLimits make_step_limits(const WorldConfig& c, const RuntimeParams& p) {
  StepLimits s;
  s.step_factor = p.step_factor;
  s.kernel_radius = c.kernel_radius;
  s.dt_min = p.dt_min;
  s.dt_max = p.dt_max;
  s.sound_speed = 0.0f;
  if (p.step_limits & kStepLimitAcoustic) s.sound_speed = speed_of_sound(make_eos(c, p));
  s.use_force_limit = (p.step_limits & kStepLimitForce) ? 1u : 0u;
  // Clavet's impulses are bounded per pair (forces.h), so only Mueller's viscosity limits dt.
  const float nu = c.viscosity_method == ViscosityMethod::Mueller ? p.viscosity / c.rest_density : 0.0f;
  s.stability_dt = stability_ceiling(c.kernel_radius, speed_of_sound(make_eos(c, p)), nu);
  if (c.features & kFeatureSprings) {
    const float springs = spring_stability_ceiling(p.spring_stiffness, p.spring_damping);
    if (springs > 0.0f && (s.stability_dt == 0.0f || springs < s.stability_dt)) s.stability_dt = springs;
  }
  return s;
}

}  // namespace sph
