// SPDX-License-Identifier: MIT
// Runtime parameters: the world's (sph_world_params) and each optional method's own struct, all
// set and read whole through one path (params_binding.h): read the caller's struct, apply the
// zero rule, validate against the methods' tables, install; and described to tools from the same
// tables. An option's struct is refused with SPH_ERROR_FEATURE_DISABLED on a world that does not
// run the method.
#include <cstddef>

#include "dfsph_solver_check.h"
#include "guard.h"
#include "handles.h"
#include "params_binding.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace sph {

// The params structs, indexed by sph_params_kind: for each, the methods whose fields it holds
// and where each field lives (one line per method; physics/methods.h is the method list).
const std::vector<ParamsBinding>& params_bindings() {
#define SPH_AT(type, field) static_cast<uint32_t>(offsetof(type, field))
  static const std::vector<ParamsBinding> table = {
      ParamsBinding{
          SPH_PARAMS_WORLD,
          "world",
          "sph_world_params",
          sizeof(sph_world_params),
          kFirstStructSize<sph_world_params>,
          nullptr,
          nullptr,
          {part<Stepping>({SPH_AT(sph_world_params, max_substeps), SPH_AT(sph_world_params, gravity),
                           SPH_AT(sph_world_params, step_factor), SPH_AT(sph_world_params, dt_min),
                           SPH_AT(sph_world_params, dt_max), SPH_AT(sph_world_params, step_limits)}),
           part<IdealGasEos>({SPH_AT(sph_world_params, stiffness)}),
           part<MuellerViscosity>({SPH_AT(sph_world_params, viscosity)}),
           part<WeaklyCompressible>({SPH_AT(sph_world_params, tension_ratio)})},
          {{"reserved0", SPH_AT(sph_world_params, reserved0)}}},
      option<SurfaceTension, sph_surface_tension_params>(
          SPH_PARAMS_SURFACE_TENSION, "sph_surface_tension_params", "SPH_FEATURE_SURFACE_TENSION",
          {SPH_AT(sph_surface_tension_params, coefficient),
           SPH_AT(sph_surface_tension_params, normal_threshold)},
          {{"reserved0", SPH_AT(sph_surface_tension_params, reserved0)}}),
      option<ClavetViscosity, sph_clavet_viscosity_params>(
          SPH_PARAMS_CLAVET_VISCOSITY, "sph_clavet_viscosity_params", "SPH_VISCOSITY_CLAVET",
          {SPH_AT(sph_clavet_viscosity_params, linear), SPH_AT(sph_clavet_viscosity_params, quadratic)},
          {{"reserved0", SPH_AT(sph_clavet_viscosity_params, reserved0)}}),
      option<TaitEos, sph_tait_params>(SPH_PARAMS_TAIT, "sph_tait_params", "SPH_EOS_TAIT",
                                       {SPH_AT(sph_tait_params, speed_of_sound)}, {}),
      option<Springs, sph_spring_params>(
          SPH_PARAMS_SPRINGS, "sph_spring_params", "SPH_FEATURE_SPRINGS",
          {SPH_AT(sph_spring_params, stiffness), SPH_AT(sph_spring_params, link_radius),
           SPH_AT(sph_spring_params, yield_ratio), SPH_AT(sph_spring_params, plasticity),
           SPH_AT(sph_spring_params, damping)},
          {{"reserved0", SPH_AT(sph_spring_params, reserved0)}}),
      option<Dfsph, sph_dfsph_params>(
          SPH_PARAMS_DFSPH, "sph_dfsph_params", "SPH_SOLVER_DFSPH",
          {SPH_AT(sph_dfsph_params, density_error), SPH_AT(sph_dfsph_params, divergence_error),
           SPH_AT(sph_dfsph_params, max_iterations), SPH_AT(sph_dfsph_params, max_divergence_iterations),
           SPH_AT(sph_dfsph_params, flags), SPH_AT(sph_dfsph_params, linear_solver),
           SPH_AT(sph_dfsph_params, density_error_max), SPH_AT(sph_dfsph_params, depth_step_factor),
           SPH_AT(sph_dfsph_params, divergence_error_per_step)},
          {}),
      option<DensityDiffusion, sph_density_diffusion_params>(
          SPH_PARAMS_DENSITY_DIFFUSION, "sph_density_diffusion_params", "SPH_FEATURE_DENSITY_DIFFUSION",
          {SPH_AT(sph_density_diffusion_params, delta)}, {}),
  };
#undef SPH_AT
  for (const ParamsBinding& b : table)
    if (b.size > kMaxPublicParamsSize)
      throw Error(Status::Internal, "params binding: a struct outgrew PublicParams");
  return table;
}

}  // namespace sph

namespace {

void require_enabled(const sph::ParamsBinding& b, const sph_world* world) {
  if (b.enabled && !b.enabled(world->world->config().selection()))
    throw Error(Status::FeatureDisabled,
                std::string("world: ") + b.requirement + " is not enabled in its sph_world_def");
}

sph_result init_params(const char* function, sph_params_kind kind, void* user, uint32_t size) {
  return sph::guarded(function, nullptr, [&] {
    const sph::ParamsBinding& b = sph::params_binding(kind, "kind");
    if (!user) throw Error(Status::InvalidArgument, "params: is NULL");
    sph::require_plausible_struct_size(size, "params", ": size ");  // before `size` bytes are cleared
    if (size < b.first_size)
      throw Error(Status::VersionMismatch, "params: size " + std::to_string(size) + " is smaller than " +
                                               std::to_string(b.first_size));
    const sph::PublicParams defaults = sph::public_params(b, sph::RuntimeParams{});
    std::memset(user, 0, size);
    std::memcpy(user, defaults.bytes, size < b.size ? size : b.size);  // an older caller's prefix
    std::memcpy(user, &size, sizeof size);
    return SPH_OK;
  });
}

sph_result set_params(const char* function, sph_world* world, uint32_t kind, const void* params) {
  return sph::guarded(function, sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::ParamsBinding& b = sph::params_binding(kind, "kind");
    require_enabled(b, world);
    const sph::PublicParams bytes = sph::read_public_params(b, params, "params");
    sph::RuntimeParams r = world->world->params();
    sph::apply_public_params(b, bytes, world->world->config().shape(), "params", r);
    sph::require_supported_dfsph_solver(*world->world, r, "params->linear_solver");
    world->world->set_params(r);
    return SPH_OK;
  });
}

sph_result get_params(const char* function, const sph_world* world, uint32_t kind, void* out) {
  return sph::guarded(function, sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::ParamsBinding& b = sph::params_binding(kind, "kind");
    require_enabled(b, world);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    uint32_t size;
    std::memcpy(&size, out, sizeof size);
    if (size < sizeof(uint32_t) * 2)
      throw Error(Status::VersionMismatch, "out->struct_size: " + std::to_string(size) +
                                               " is too small; fill the struct with its _init() function");
    const sph::PublicParams bytes = sph::public_params(b, world->world->params());
    std::memcpy(out, bytes.bytes, size < b.size ? size : b.size);
    std::memcpy(out, &size, sizeof size);
    return SPH_OK;
  });
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_world_set_physics_params(sph_world* world, sph_params_kind kind,
                                                         const void* params) {
  return set_params("sph_world_set_physics_params", world, sph::enum_bits(kind), params);
}
SPH_API sph_result SPH_CALL sph_world_get_physics_params(const sph_world* world, sph_params_kind kind,
                                                         void* out) {
  return get_params("sph_world_get_physics_params", world, sph::enum_bits(kind), out);
}

SPH_API sph_result SPH_CALL sph_world_params_init_sized(sph_world_params* params, uint32_t size) {
  return init_params("sph_world_params_init", SPH_PARAMS_WORLD, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_params(sph_world* world, const sph_world_params* params) {
  return set_params("sph_world_set_params", world, SPH_PARAMS_WORLD, params);
}
SPH_API sph_result SPH_CALL sph_world_get_params(const sph_world* world, sph_world_params* out) {
  return get_params("sph_world_get_params", world, SPH_PARAMS_WORLD, out);
}

SPH_API sph_result SPH_CALL sph_surface_tension_params_init_sized(sph_surface_tension_params* params,
                                                                  uint32_t size) {
  return init_params("sph_surface_tension_params_init", SPH_PARAMS_SURFACE_TENSION, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_surface_tension_params(sph_world* world,
                                                                 const sph_surface_tension_params* params) {
  return set_params("sph_world_set_surface_tension_params", world, SPH_PARAMS_SURFACE_TENSION, params);
}
SPH_API sph_result SPH_CALL sph_world_get_surface_tension_params(const sph_world* world,
                                                                 sph_surface_tension_params* out) {
  return get_params("sph_world_get_surface_tension_params", world, SPH_PARAMS_SURFACE_TENSION, out);
}

SPH_API sph_result SPH_CALL sph_clavet_viscosity_params_init_sized(sph_clavet_viscosity_params* params,
                                                                   uint32_t size) {
  return init_params("sph_clavet_viscosity_params_init", SPH_PARAMS_CLAVET_VISCOSITY, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_clavet_viscosity_params(sph_world* world,
                                                                  const sph_clavet_viscosity_params* params) {
  return set_params("sph_world_set_clavet_viscosity_params", world, SPH_PARAMS_CLAVET_VISCOSITY, params);
}
SPH_API sph_result SPH_CALL sph_world_get_clavet_viscosity_params(const sph_world* world,
                                                                  sph_clavet_viscosity_params* out) {
  return get_params("sph_world_get_clavet_viscosity_params", world, SPH_PARAMS_CLAVET_VISCOSITY, out);
}

SPH_API sph_result SPH_CALL sph_tait_params_init_sized(sph_tait_params* params, uint32_t size) {
  return init_params("sph_tait_params_init", SPH_PARAMS_TAIT, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_tait_params(sph_world* world, const sph_tait_params* params) {
  return set_params("sph_world_set_tait_params", world, SPH_PARAMS_TAIT, params);
}
SPH_API sph_result SPH_CALL sph_world_get_tait_params(const sph_world* world, sph_tait_params* out) {
  return get_params("sph_world_get_tait_params", world, SPH_PARAMS_TAIT, out);
}

SPH_API sph_result SPH_CALL sph_spring_params_init_sized(sph_spring_params* params, uint32_t size) {
  return init_params("sph_spring_params_init", SPH_PARAMS_SPRINGS, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_spring_params(sph_world* world, const sph_spring_params* params) {
  return set_params("sph_world_set_spring_params", world, SPH_PARAMS_SPRINGS, params);
}
SPH_API sph_result SPH_CALL sph_world_get_spring_params(const sph_world* world, sph_spring_params* out) {
  return get_params("sph_world_get_spring_params", world, SPH_PARAMS_SPRINGS, out);
}

SPH_API sph_result SPH_CALL sph_dfsph_params_init_sized(sph_dfsph_params* params, uint32_t size) {
  return init_params("sph_dfsph_params_init", SPH_PARAMS_DFSPH, params, size);
}
SPH_API sph_result SPH_CALL sph_world_set_dfsph_params(sph_world* world, const sph_dfsph_params* params) {
  return set_params("sph_world_set_dfsph_params", world, SPH_PARAMS_DFSPH, params);
}
SPH_API sph_result SPH_CALL sph_world_get_dfsph_params(const sph_world* world, sph_dfsph_params* out) {
  return get_params("sph_world_get_dfsph_params", world, SPH_PARAMS_DFSPH, out);
}

SPH_API sph_result SPH_CALL sph_density_diffusion_params_init_sized(sph_density_diffusion_params* params,
                                                                    uint32_t size) {
  return init_params("sph_density_diffusion_params_init", SPH_PARAMS_DENSITY_DIFFUSION, params, size);
}
SPH_API sph_result SPH_CALL
sph_world_set_density_diffusion_params(sph_world* world, const sph_density_diffusion_params* params) {
  return set_params("sph_world_set_density_diffusion_params", world, SPH_PARAMS_DENSITY_DIFFUSION, params);
}
SPH_API sph_result SPH_CALL sph_world_get_density_diffusion_params(const sph_world* world,
                                                                   sph_density_diffusion_params* out) {
  return get_params("sph_world_get_density_diffusion_params", world, SPH_PARAMS_DENSITY_DIFFUSION, out);
}

}  // extern "C"
