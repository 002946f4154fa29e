// SPDX-License-Identifier: MIT
// The method list: every physics method of the library and the one order in which everything
// that visits them does (constants, validation, checkpoints, the force composer). Each method is
// a module of its own header (Params with its table, Constants, terms, step ceiling, arrays);
// this file composes them. Adding a method: docs/architecture.md, "How to add a physics method".
#pragma once

#include <stdint.h>

#include <type_traits>

#include "boundary_density.h"
#include "collider_loads.h"
#include "density_diffusion.h"
#include "density_normalization.h"
#include "dfsph.h"
#include "eos_ideal_gas.h"
#include "eos_tait.h"
#include "pressure_force.h"
#include "springs.h"
#include "step_control.h"
#include "surface_tension.h"
#include "viscosity_clavet.h"
#include "viscosity_mueller.h"
#include "weakly_compressible.h"
#include "world_shape.h"

namespace sph {

// ---- which methods a world runs, fixed at creation (sph_world_def) --------------------------
// Feature bits, equal to the SPH_FEATURE_* values of the C header.
enum FeatureBits : uint32_t {
  kFeatureSurfaceTension = 1u << 0,
  kFeatureNormalizedDensity = 1u << 1,
  kFeatureSprings = 1u << 2,
  kFeatureBoundaryDensity = 1u << 3,
  kFeatureColliderLoads = 1u << 4,
  kFeatureUserAttribute = 1u << 5,  // no physics: a carried uint32 (core/particle_arrays.h)
  kFeatureDensityDiffusion = 1u << 6,
  kFeatureAll = kFeatureSurfaceTension | kFeatureNormalizedDensity | kFeatureSprings |
                kFeatureBoundaryDensity | kFeatureColliderLoads | kFeatureUserAttribute |
                kFeatureDensityDiffusion,
};

enum class ViscosityMethod : uint32_t { Mueller = 0, Clavet = 1 };

// ---- the equation of state: pressure from density, by the world's choice of the EOS methods --
// The choice is made at run time, per density evaluation: a branch on a value every thread
// shares, cheaper than another template dimension.
enum class EquationOfState : uint32_t { IdealGas = 0, Tait = 1 };

// The solver: the thesis's weakly compressible scheme, or DFSPH (dfsph.h). Equal to sph_solver.
enum class Solver : uint32_t { WeaklyCompressible = 0, Dfsph = 1 };

struct EosConstants {
  EquationOfState kind;
  float rest_density;   // rho0
  float tension_floor;  // (1 - tau) rho0: the law holds down to it (WeaklyCompressible::tension_floor)
  IdealGasEos::Constants ideal_gas;
  TaitEos::Constants tait;
};

// Both laws are held at their value at the tension floor (1 - tau) rho0 below it, tau the
// world's tension_ratio (sph_world_params; default 0, the floor at rho0: the clamp at zero).
// Why a floor: particles at a free surface miss neighbours, so their summed density is low; an
// unbounded law turns that deficit into a strong tension that pulls surface particles into
// clumps and flings them off (the tensile instability). The clamp at zero is the usual
// weakly-compressible SPH treatment: the fluid resists compression and the free surface is left
// alone (cohesion belongs to surface tension). Its cost: a fluid that cannot pull swells at no
// cost wherever it is disturbed (the rest sphere's interior 2.7 % below rho0), and the pressure
// noise at a wall is rectified into a positive mean (docs/validation.md, session 21). A small tau
// lets the law pull a little, down to p((1 - tau) rho0) = -k tau rho0 for the ideal gas, while
// the surface, tau and more below rho0, is held at that bounded tension (docs/physics.md).
// A NaN density stays NaN (the comparison is false), so the non-finite diagnosis still sees it.
SPH_HD float pressure_from_density(const EosConstants& e, float density) {
  const float rho = density < e.tension_floor ? e.tension_floor : density;
  if (e.kind == EquationOfState::Tait) return TaitEos::pressure(e.tait, rho, e.rest_density);
  return IdealGasEos::pressure(e.ideal_gas, rho - e.rest_density);
}

// The numerical speed of sound of the law at rest density (for the acoustic step limit).
SPH_HD float speed_of_sound(const EosConstants& e) {
  const float c2 = e.kind == EquationOfState::Tait ? TaitEos::squared_sound_speed(e.tait, e.rest_density)
                                                   : IdealGasEos::squared_sound_speed(e.ideal_gas);
  return c2 > 0.0f ? SPH_SQRTF(c2) : 0.0f;
}

struct MethodSelection {
  uint32_t features = 0;  // FeatureBits
  ViscosityMethod viscosity = ViscosityMethod::Mueller;
  EquationOfState equation_of_state = EquationOfState::IdealGas;
  Solver solver = Solver::WeaklyCompressible;
};

// How a world turns a method on (values equal to sph_method_switch): a feature bit, or a value
// of one of sph_world_def's method fields.
enum class SwitchKind : uint32_t { Feature = 1, Viscosity = 2, EquationOfState = 3, Solver = 4 };
struct MethodSwitch {
  SwitchKind kind;
  uint32_t value;
};

constexpr MethodSwitch switch_of(Tag<IdealGasEos>) {
  return {SwitchKind::EquationOfState, static_cast<uint32_t>(EquationOfState::IdealGas)};
}
constexpr MethodSwitch switch_of(Tag<TaitEos>) {
  return {SwitchKind::EquationOfState, static_cast<uint32_t>(EquationOfState::Tait)};
}
constexpr MethodSwitch switch_of(Tag<MuellerViscosity>) {
  return {SwitchKind::Viscosity, static_cast<uint32_t>(ViscosityMethod::Mueller)};
}
constexpr MethodSwitch switch_of(Tag<ClavetViscosity>) {
  return {SwitchKind::Viscosity, static_cast<uint32_t>(ViscosityMethod::Clavet)};
}
constexpr MethodSwitch switch_of(Tag<SurfaceTension>) {
  return {SwitchKind::Feature, kFeatureSurfaceTension};
}
constexpr MethodSwitch switch_of(Tag<NormalizedDensity>) {
  return {SwitchKind::Feature, kFeatureNormalizedDensity};
}
constexpr MethodSwitch switch_of(Tag<Springs>) { return {SwitchKind::Feature, kFeatureSprings}; }
constexpr MethodSwitch switch_of(Tag<WeaklyCompressible>) {
  return {SwitchKind::Solver, static_cast<uint32_t>(Solver::WeaklyCompressible)};
}
constexpr MethodSwitch switch_of(Tag<Dfsph>) {
  return {SwitchKind::Solver, static_cast<uint32_t>(Solver::Dfsph)};
}
constexpr MethodSwitch switch_of(Tag<BoundaryDensity>) {
  return {SwitchKind::Feature, kFeatureBoundaryDensity};
}
constexpr MethodSwitch switch_of(Tag<ColliderLoads>) { return {SwitchKind::Feature, kFeatureColliderLoads}; }
constexpr MethodSwitch switch_of(Tag<DensityDiffusion>) {
  return {SwitchKind::Feature, kFeatureDensityDiffusion};
}

// Calls visit(Tag<Method>{}) for every method a world can choose, in the list's order.
template <class Visit>
void for_each_method(Visit&& visit) {
  visit(Tag<IdealGasEos>{});
  visit(Tag<TaitEos>{});
  visit(Tag<MuellerViscosity>{});
  visit(Tag<ClavetViscosity>{});
  visit(Tag<SurfaceTension>{});
  visit(Tag<NormalizedDensity>{});
  visit(Tag<Springs>{});
  visit(Tag<WeaklyCompressible>{});
  visit(Tag<Dfsph>{});
  visit(Tag<BoundaryDensity>{});
  visit(Tag<ColliderLoads>{});
  visit(Tag<DensityDiffusion>{});
}

// Whether a value of a sph_world_def method field (or a feature bit) names a method of the list,
// so that a def or checkpoint naming a method added here is accepted without more code.
inline bool selects_a_method(SwitchKind kind, uint32_t value) {
  bool found = false;
  for_each_method([&](auto tag) {
    const MethodSwitch m = switch_of(tag);
    found = found || (m.kind == kind && m.value == value);
  });
  return found;
}

constexpr bool selects(const MethodSelection& s, MethodSwitch m) {
  return m.kind == SwitchKind::Feature           ? (s.features & m.value) != 0
         : m.kind == SwitchKind::Viscosity       ? static_cast<uint32_t>(s.viscosity) == m.value
         : m.kind == SwitchKind::EquationOfState ? static_cast<uint32_t>(s.equation_of_state) == m.value
                                                 : static_cast<uint32_t>(s.solver) == m.value;
}
// Whether a world runs a method (the world's stepping always runs; the symmetric pressure force
// with the weakly compressible solver).
template <class Method>
bool runs(const MethodSelection& s, Tag<Method> method) {
  return selects(s, switch_of(method));
}

// ---- runtime parameters: every method's Params, whether the world runs it or not -------------
struct MethodParams {
  IdealGasEos::Params ideal_gas;
  TaitEos::Params tait;
  MuellerViscosity::Params mueller;
  ClavetViscosity::Params clavet;
  SurfaceTension::Params surface_tension;
  Springs::Params springs;
  Dfsph::Params dfsph;
  DensityDiffusion::Params density_diffusion;
  WeaklyCompressible::Params wcsph;
};

// Calls visit(Tag<Method>{}, params) for each method with parameters, in the list's order (the
// order of checkpoints). Params is MethodParams or const MethodParams.
template <class Params, class Visit>
void for_each_method_params(Params& p, Visit&& visit) {
  visit(Tag<IdealGasEos>{}, p.ideal_gas);
  visit(Tag<TaitEos>{}, p.tait);
  visit(Tag<MuellerViscosity>{}, p.mueller);
  visit(Tag<ClavetViscosity>{}, p.clavet);
  visit(Tag<SurfaceTension>{}, p.surface_tension);
  visit(Tag<Springs>{}, p.springs);
  visit(Tag<Dfsph>{}, p.dfsph);
  visit(Tag<DensityDiffusion>{}, p.density_diffusion);  // checkpoints before format 4 lack its block
  visit(Tag<WeaklyCompressible>{}, p.wcsph);            // last: checkpoints before format 11 lack its block
}

// ---- constants: derived per frame from the Params and the world's shape ---------------------
// A method the world does not run gets zero constants (nothing reads them).
struct MethodConstants {
  EosConstants eos;  // the world's equation of state (both laws' constants, one chosen)
  MuellerViscosity::Constants mueller;
  ClavetViscosity::Constants clavet;
  SurfaceTension::Constants surface_tension;
  Springs::Constants springs;
  Dfsph::Constants dfsph;
  BoundaryDensity::Constants boundary;
  DensityDiffusion::Constants density_diffusion;
};

inline EosConstants make_eos_constants(const MethodParams& p, const MethodSelection& s,
                                       const WorldShape& shape) {
  EosConstants e;
  e.kind = s.equation_of_state;
  e.rest_density = shape.rest_density;
  e.tension_floor = WeaklyCompressible::tension_floor(p.wcsph, shape);
  e.ideal_gas = IdealGasEos::make_constants(p.ideal_gas);
  e.tait = TaitEos::make_constants(p.tait, shape);
  return e;
}

inline MethodConstants make_method_constants(const MethodParams& p, const MethodSelection& s,
                                             const WorldShape& shape, const LatticeSums& lattice,
                                             Vec3 gravity) {
  MethodConstants m{};
  m.eos = make_eos_constants(p, s, shape);
  if (runs(s, Tag<MuellerViscosity>{})) m.mueller = MuellerViscosity::make_constants(p.mueller);
  if (runs(s, Tag<ClavetViscosity>{})) m.clavet = ClavetViscosity::make_constants(p.clavet);
  if (runs(s, Tag<SurfaceTension>{}))
    m.surface_tension = SurfaceTension::make_constants(p.surface_tension, shape, lattice);
  if (runs(s, Tag<Springs>{})) m.springs = Springs::make_constants(p.springs, shape);
  if (runs(s, Tag<Dfsph>{})) m.dfsph = Dfsph::make_constants(p.dfsph, shape, lattice);
  if (runs(s, Tag<BoundaryDensity>{})) m.boundary = BoundaryDensity::make_constants(shape, lattice);
  if (runs(s, Tag<DensityDiffusion>{}))
    m.density_diffusion =
        DensityDiffusion::make_constants(p.density_diffusion, shape, speed_of_sound(m.eos), gravity);
  return m;
}

// The force terms read their constants by tag (forces.h).
SPH_HD const MuellerViscosity::Constants& constants_of(const MethodConstants& m, Tag<MuellerViscosity>) {
  return m.mueller;
}
SPH_HD const ClavetViscosity::Constants& constants_of(const MethodConstants& m, Tag<ClavetViscosity>) {
  return m.clavet;
}
SPH_HD const SurfaceTension::Constants& constants_of(const MethodConstants& m, Tag<SurfaceTension>) {
  return m.surface_tension;
}

// ---- the stability ceiling: the smallest of the running methods' ceilings (0: none) ---------
// The acoustic ceiling is the weakly compressible scheme's: DFSPH has no equation of state.
inline float method_stability_ceiling(const MethodParams& p, const MethodSelection& s,
                                      const WorldShape& shape) {
  const EosConstants eos = make_eos_constants(p, s, shape);
  float dt = 0.0f;
  auto take = [&dt](float ceiling) {
    if (ceiling > 0.0f && (dt == 0.0f || ceiling < dt)) dt = ceiling;
  };
  if (runs(s, Tag<WeaklyCompressible>{}))
    take(SymmetricPressure::stability_ceiling(shape.kernel_radius, speed_of_sound(eos)));
  if (runs(s, Tag<MuellerViscosity>{})) take(MuellerViscosity::stability_ceiling(p.mueller, shape));
  if (runs(s, Tag<Springs>{})) take(Springs::stability_ceiling(p.springs));
  return dt;
}

// ---- the force terms after the pressure force, in the order they add to the acceleration ----
template <class... Terms>
struct ForceTerms {};

// A place in the force pass that one of its alternatives fills, in the order they are listed:
// the first that the world runs, else the last (the default, or NoTerm for an option that is off).
template <class... Alternatives>
struct Slot {};
struct NoTerm {};

// The force pass's slots, in the order their terms add to the acceleration.
using ForceSlots = ForceTerms<Slot<ClavetViscosity, MuellerViscosity>, Slot<SurfaceTension, NoTerm>>;

template <class Chosen, class Slots>
struct ForceDispatch;
template <class... Chosen>
struct ForceDispatch<ForceTerms<Chosen...>, ForceTerms<>> {
  template <class F>
  static auto run(const MethodSelection&, F&& f) {
    return f(ForceTerms<Chosen...>{});
  }
};
template <class... Chosen, class... Alternatives, class... Rest>
struct ForceDispatch<ForceTerms<Chosen...>, ForceTerms<Slot<Alternatives...>, Rest...>> {
  template <class F>
  static auto run(const MethodSelection& s, F&& f) {
    return pick<Alternatives...>(s, f);
  }
  template <class Alternative, class... Others, class F>
  static auto pick(const MethodSelection& s, F&& f) {
    if constexpr (sizeof...(Others) == 0) {
      return take<Alternative>(s, f);
    } else {
      if (runs(s, Tag<Alternative>{})) return take<Alternative>(s, f);
      return pick<Others...>(s, f);
    }
  }
  template <class Alternative, class F>
  static auto take(const MethodSelection& s, F&& f) {
    using Next = std::conditional_t<std::is_same<Alternative, NoTerm>::value, ForceTerms<Chosen...>,
                                    ForceTerms<Chosen..., Alternative>>;
    return ForceDispatch<Next, ForceTerms<Rest...>>::run(s, f);
  }
};

// Calls f(ForceTerms<...>{}) with the terms a world runs, each a compile-time type, so a backend
// instantiates its force pass once per combination and a method that is off compiles away.
template <class F>
auto with_force_terms(const MethodSelection& s, F&& f) {
  return ForceDispatch<ForceTerms<>, ForceSlots>::run(s, f);
}

}  // namespace sph
