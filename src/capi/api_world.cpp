// SPDX-License-Identifier: MIT
// Worlds: creation from a def (runtime parameters: api_physics_options.cpp).
#include <cfloat>

#include "../core/fcc_lattice.h"
#include "../core/kernel_radius_rule.h"
#include "../physics/kernels.h"
#include "guard.h"
#include "handles.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

constexpr uint32_t kMaxCapacity = sph::kMaxWorldCapacity;
constexpr float kDefaultKernelRadiusFactor = 1.8f;  // between the 3rd (sqrt 3) and 4th (2) FCC shell

sph_world_def default_world_def() {
  sph_world_def d;
  std::memset(&d, 0, sizeof d);
  d.struct_size = sizeof d;
  d.capacity = 65536;
  d.features = SPH_FEATURE_NONE;
  d.integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
  d.particle_spacing = 0.02f;
  d.kernel_radius = 0.0f;
  d.rest_density = 1000.0f;
  d.solver = SPH_SOLVER_WCSPH;
  return d;
}

// DFSPH's combinations (docs/physics.md, "DFSPH: the incompressible solver"): what it does not support is
// refused here, naming the field, rather than run with a meaning the caller did not ask for.
void require_dfsph_combination(const sph_world_def& d, uint32_t integrator, uint32_t eos) {
  if (integrator == SPH_INTEGRATOR_RK4)
    throw Error(Status::Unsupported,
                "def->integrator: SPH_INTEGRATOR_RK4 with def->solver SPH_SOLVER_DFSPH; DFSPH is its own "
                "time integration (a velocity update per solve, then positions), use "
                "SPH_INTEGRATOR_SYMPLECTIC_EULER");
  if (eos != SPH_EOS_IDEAL_GAS)
    throw Error(Status::Unsupported,
                "def->equation_of_state: SPH_SOLVER_DFSPH has no equation of state (its pressure comes from "
                "its solves); leave it at SPH_EOS_IDEAL_GAS (unused)");
  if (d.features & SPH_FEATURE_NORMALIZED_DENSITY)
    throw Error(
        Status::Unsupported,
        "def->features: SPH_FEATURE_NORMALIZED_DENSITY with def->solver SPH_SOLVER_DFSPH; the carried "
        "density factor corrects a weakly compressible surface, while DFSPH's density solve acts only "
        "on compression, which a surface deficit never reads");
  if (d.features & SPH_FEATURE_DENSITY_DIFFUSION)
    throw Error(Status::Unsupported,
                "def->features: SPH_FEATURE_DENSITY_DIFFUSION with def->solver SPH_SOLVER_DFSPH; the "
                "diffusion acts on the weakly compressible solver's carried density, DFSPH's density "
                "solve has none");
}

// Validates a def and resolves defaults into the internal configuration. Zero means default
// for every field (a zeroed def, struct_size set, is the def sph_world_def_init gives).
sph::WorldConfig config_from_def(const sph_world_def& def) {
  const sph_world_def defaults = default_world_def();
  sph_world_def d = def;
  if (d.capacity == 0) d.capacity = defaults.capacity;
  if (d.particle_spacing == 0.0f) d.particle_spacing = defaults.particle_spacing;
  if (d.rest_density == 0.0f) d.rest_density = defaults.rest_density;
  if (d.header_version != 0 && (d.header_version >> 22) != SPH_VERSION_MAJOR)
    throw Error(Status::VersionMismatch,
                "def->header_version: the caller's header has another major version");
  if (d.capacity > kMaxCapacity)
    throw Error(Status::InvalidArgument, "def->capacity: must be at most 2^30 (0 = the default 65536), got " +
                                             std::to_string(d.capacity));
  if (d.max_capacity != 0 && (d.max_capacity < d.capacity || d.max_capacity > kMaxCapacity))
    throw Error(Status::InvalidArgument,
                "def->max_capacity: must be 0 (a fixed world) or in [def->capacity " +
                    std::to_string(d.capacity) + ", 2^30], got " + std::to_string(d.max_capacity));
  if (d.features & ~static_cast<uint32_t>(sph::kFeatureAll)) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", d.features & ~static_cast<uint32_t>(sph::kFeatureAll));
    throw Error(Status::Unsupported, std::string("def->features: unknown feature bits 0x") + buf);
  }
  const uint32_t integrator = sph::enum_bits(d.integrator);
  if (integrator != SPH_INTEGRATOR_SYMPLECTIC_EULER && integrator != SPH_INTEGRATOR_RK4)
    throw Error(Status::Unsupported, "def->integrator: " + std::to_string(static_cast<int32_t>(integrator)) +
                                         " is not an sph_integrator value");
  const uint32_t viscosity = sph::enum_bits(d.viscosity_method);
  if (!sph::selects_a_method(sph::SwitchKind::Viscosity, viscosity))
    throw Error(Status::Unsupported,
                "def->viscosity_method: " + std::to_string(static_cast<int32_t>(viscosity)) +
                    " is not an sph_viscosity_method value");
  const uint32_t eos = sph::enum_bits(d.equation_of_state);
  if (!sph::selects_a_method(sph::SwitchKind::EquationOfState, eos))
    throw Error(Status::Unsupported, "def->equation_of_state: " + std::to_string(static_cast<int32_t>(eos)) +
                                         " is not an sph_equation_of_state value");
  const uint32_t solver = sph::enum_bits(d.solver);
  if (!sph::selects_a_method(sph::SwitchKind::Solver, solver))
    throw Error(Status::Unsupported, "def->solver: " + std::to_string(static_cast<int32_t>(solver)) +
                                         " is not an sph_solver value");
  if (solver == SPH_SOLVER_DFSPH) require_dfsph_combination(d, integrator, eos);
  if ((d.features & SPH_FEATURE_DENSITY_DIFFUSION) && !(d.features & SPH_FEATURE_NORMALIZED_DENSITY))
    throw Error(Status::Unsupported,
                "def->features: SPH_FEATURE_DENSITY_DIFFUSION needs SPH_FEATURE_NORMALIZED_DENSITY; the "
                "diffusion is a term of the continuity equation and acts on the carried density, while the "
                "plain summation is recomputed from the positions every substep");
  sph::require_positive(d.particle_spacing, "def->particle_spacing");
  sph::require_positive(d.rest_density, "def->rest_density");
  float h = d.kernel_radius;
  if (h == 0.0f) {
    h = kDefaultKernelRadiusFactor * d.particle_spacing;
  } else {
    sph::require_positive(h, "def->kernel_radius");
    if (const char* fault = sph::kernel_radius_fault(d.particle_spacing, h))
      throw Error(Status::InvalidArgument, "def->kernel_radius: " + sph::describe(h) + " " + fault +
                                               " (def->particle_spacing " +
                                               sph::describe(d.particle_spacing) + ")");
  }
  const sph::KernelCoefficients k = sph::make_kernel_coefficients(h);
  const bool representable = std::isfinite(h) && std::isfinite(k.poly6) && std::isfinite(k.spiky_grad) &&
                             k.poly6 > 0.0f && k.visc_lap > 0.0f && std::isnormal(k.h2);
  const float mass = representable ? sph::fcc_rest_mass(d.particle_spacing, h, d.rest_density) : 0.0f;
  if (!representable || !std::isfinite(mass) || !(mass > 0.0f) || !std::isnormal(mass))
    throw Error(Status::InvalidArgument, "def->particle_spacing: " + sph::describe(d.particle_spacing) +
                                             " m gives kernel coefficients or a particle mass that float32 "
                                             "cannot represent; choose other units or spacing");
  sph::WorldConfig c;
  c.capacity = d.capacity;
  c.max_capacity = d.max_capacity == 0 ? d.capacity : d.max_capacity;
  c.features = d.features;
  c.integrator = static_cast<sph::Integrator>(integrator);
  c.viscosity_method = static_cast<sph::ViscosityMethod>(viscosity);
  c.equation_of_state = static_cast<sph::EquationOfState>(eos);
  c.solver = static_cast<sph::Solver>(solver);
  c.particle_spacing = d.particle_spacing;
  c.kernel_radius = h;
  c.rest_density = d.rest_density;
  c.particle_mass = mass;
  c.spiky_scale = sph::fcc_spiky_scale(d.particle_spacing, h);
  c.density_self_weight =
      sph::fcc_density_self_weight(d.particle_spacing, h, d.rest_density, mass, c.spiky_scale);
  if (!std::isfinite(c.density_self_weight))
    throw Error(Status::InvalidArgument,
                "def->kernel_radius: " + sph::describe(h) +
                    " gives a non-finite density self term with def->particle_spacing " +
                    sph::describe(d.particle_spacing));
  return c;
}

}  // namespace

// (handles.h) The world that sph_world_create makes, unpublished: libsph_mpi's
// sph_mpi_world_create makes its rank's world with it.
std::unique_ptr<sph_world> sph::make_world(sph_context* context, const sph_world_def& def) {
  const sph::WorldConfig config = config_from_def(def);
  auto backend = sph::make_backend(context->backend, config, context->device_ordinal, context->cpu_workers,
                                   context->cpu_tasks, context->cuda_tuning);
  auto world = std::make_unique<sph_world>();
  world->context = context;
  world->world = std::make_unique<sph::World>(config, std::move(backend));
  world->world->set_id_tag(sph::next_world_tag(context));
  return world;
}

uint16_t sph::next_world_tag(sph_context* context) {
  const uint32_t n = context->worlds_made.fetch_add(1, std::memory_order_relaxed);  // 0 for the first
  return static_cast<uint16_t>(n % 65535u + 1u);
}

extern "C" {

SPH_API sph_result SPH_CALL sph_world_def_init_sized(sph_world_def* def, uint32_t size) {
  return sph::guarded("sph_world_def_init", nullptr, [&] {
    sph::require_init_size(def, size, "def");
    sph::write_user_struct(def, size, default_world_def());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_create(sph_context* context, const sph_world_def* def,
                                             sph_world** out) {
  return sph::guarded("sph_world_create", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const sph_world_def d = sph::read_user_struct(def, "def");
    sph_world* world = sph::publish_world(sph::make_world(context, d));
    *out = world;
    // Legal, and a trap for a floating body: without the walls in the density the pressure the
    // fluid holds a wall with is not a load (docs/api.md, log_fn).
    if ((d.features & SPH_FEATURE_COLLIDER_LOADS) && !(d.features & SPH_FEATURE_BOUNDARY_DENSITY))
      sph::report_warning(
          sph::log_target_of(world), "sph_world_create",
          "SPH_FEATURE_COLLIDER_LOADS without SPH_FEATURE_BOUNDARY_DENSITY: the loads are the "
          "collision response's contact impulses alone, so a body the fluid holds off by its "
          "pressure feels none of it (a submerged box reads almost no buoyancy); add "
          "SPH_FEATURE_BOUNDARY_DENSITY for the walls' pressure");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_destroy(sph_world* world) {
  if (!world) {
    sph::clear_last_error();
    return SPH_OK;
  }
  return sph::guarded("sph_world_destroy", sph::context_of(world), [&] {
    // The world leaves the registry in the critical section that takes its lock, so no other
    // call can be inside it or enter it afterwards.
    const sph::Take take = sph::try_retire_world(world);
    if (take == sph::Take::NotLive)
      throw Error(Status::InvalidHandle, "world: is not a live sph_world (destroyed or foreign pointer)");
    if (take == sph::Take::Busy)
      throw Error(Status::WorldLocked,
                  "world: is in use by another call; destroy it when that call returned");
    delete world;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_def(const sph_world* world, sph_world_def* out_def) {
  return sph::guarded("sph_world_get_def", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_def) throw Error(Status::InvalidArgument, "out_def: is NULL");
    const sph::WorldConfig& c = world->world->config();
    sph_world_def d = default_world_def();
    d.header_version = SPH_VERSION;
    d.capacity = c.capacity;
    d.max_capacity = c.max_capacity;
    d.features = c.features;
    d.integrator = static_cast<sph_integrator>(c.integrator);
    d.viscosity_method = static_cast<sph_viscosity_method>(c.viscosity_method);
    d.equation_of_state = static_cast<sph_equation_of_state>(c.equation_of_state);
    d.solver = static_cast<sph_solver>(c.solver);
    d.particle_spacing = c.particle_spacing;
    d.kernel_radius = c.kernel_radius;
    d.rest_density = c.rest_density;
    sph::write_output_struct(out_def, d, "out_def");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_particle_mass(const sph_world* world, float* out_mass) {
  return sph::guarded("sph_world_get_particle_mass", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_mass) throw Error(Status::InvalidArgument, "out_mass: is NULL");
    *out_mass = world->world->config().particle_mass;
    return SPH_OK;
  });
}

}  // extern "C"
