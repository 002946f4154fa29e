// Parameters of optional physics: each option has its own struct, set and read whole, and is
// refused with SPH_ERROR_FEATURE_DISABLED on a world that did not turn the option on.
#include "../core/config.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

void require_feature(bool enabled, const char* what) {
  if (!enabled)
    throw Error(Status::FeatureDisabled,
                std::string("world: ") + what + " is not enabled in its sph_world_def");
}

bool has_surface_tension(const sph_world* w) {
  return (w->world->config().features & sph::kFeatureSurfaceTension) != 0;
}
bool has_clavet(const sph_world* w) {
  return w->world->config().viscosity_method == sph::ViscosityMethod::Clavet;
}
bool has_springs(const sph_world* w) { return (w->world->config().features & sph::kFeatureSprings) != 0; }
bool has_tait(const sph_world* w) {
  return w->world->config().equation_of_state == sph::EquationOfState::Tait;
}

// Applies a change to a copy of the world's runtime parameters and installs it.
template <class Change>
void update_params(sph_world* world, Change&& change) {
  sph::RuntimeParams p = world->world->params();
  change(p);
  world->world->set_params(p);
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_surface_tension_params_init_sized(sph_surface_tension_params* params,
                                                                  uint32_t size) {
  return sph::init_user_struct("sph_surface_tension_params_init", "params", params, size,
                               [](sph_surface_tension_params& d) {
                                 const sph::RuntimeParams defaults;
                                 d.coefficient = defaults.surface_tension;
                                 d.normal_threshold = defaults.surface_threshold;
                               });
}

SPH_API sph_result SPH_CALL sph_world_set_surface_tension_params(sph_world* world,
                                                                 const sph_surface_tension_params* params) {
  return sph::guarded("sph_world_set_surface_tension_params", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_feature(has_surface_tension(world), "SPH_FEATURE_SURFACE_TENSION");
    const sph_surface_tension_params p = sph::read_user_struct(params, "params");
    sph::require_non_negative(p.coefficient, "params->coefficient");
    sph::require_non_negative(p.normal_threshold, "params->normal_threshold");
    sph::require_zero(p.reserved0, "params->reserved0");
    update_params(world, [&](sph::RuntimeParams& r) {
      r.surface_tension = p.coefficient;
      r.surface_threshold = p.normal_threshold;
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_surface_tension_params(const sph_world* world,
                                                                 sph_surface_tension_params* out) {
  return sph::guarded("sph_world_get_surface_tension_params", sph::context_of(world), [&] {
    sph::require_world(world);
    require_feature(has_surface_tension(world), "SPH_FEATURE_SURFACE_TENSION");
    sph_surface_tension_params p;
    std::memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.coefficient = world->world->params().surface_tension;
    p.normal_threshold = world->world->params().surface_threshold;
    sph::write_output_struct(out, p, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_clavet_viscosity_params_init_sized(sph_clavet_viscosity_params* params,
                                                                   uint32_t size) {
  return sph::init_user_struct("sph_clavet_viscosity_params_init", "params", params, size,
                               [](sph_clavet_viscosity_params& d) {
                                 const sph::RuntimeParams defaults;
                                 d.linear = defaults.clavet_linear;
                                 d.quadratic = defaults.clavet_quadratic;
                               });
}

SPH_API sph_result SPH_CALL sph_world_set_clavet_viscosity_params(sph_world* world,
                                                                  const sph_clavet_viscosity_params* params) {
  return sph::guarded("sph_world_set_clavet_viscosity_params", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_feature(has_clavet(world), "SPH_VISCOSITY_CLAVET");
    const sph_clavet_viscosity_params p = sph::read_user_struct(params, "params");
    sph::require_non_negative(p.linear, "params->linear");
    sph::require_non_negative(p.quadratic, "params->quadratic");
    sph::require_zero(p.reserved0, "params->reserved0");
    update_params(world, [&](sph::RuntimeParams& r) {
      r.clavet_linear = p.linear;
      r.clavet_quadratic = p.quadratic;
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_clavet_viscosity_params(const sph_world* world,
                                                                  sph_clavet_viscosity_params* out) {
  return sph::guarded("sph_world_get_clavet_viscosity_params", sph::context_of(world), [&] {
    sph::require_world(world);
    require_feature(has_clavet(world), "SPH_VISCOSITY_CLAVET");
    sph_clavet_viscosity_params p;
    std::memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.linear = world->world->params().clavet_linear;
    p.quadratic = world->world->params().clavet_quadratic;
    sph::write_output_struct(out, p, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_tait_params_init_sized(sph_tait_params* params, uint32_t size) {
  return sph::init_user_struct("sph_tait_params_init", "params", params, size, [](sph_tait_params& d) {
    const sph::RuntimeParams defaults;
    d.speed_of_sound = defaults.tait_sound_speed;
  });
}

SPH_API sph_result SPH_CALL sph_world_set_tait_params(sph_world* world, const sph_tait_params* params) {
  return sph::guarded("sph_world_set_tait_params", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_feature(has_tait(world), "SPH_EOS_TAIT");
    const sph_tait_params p = sph::read_user_struct(params, "params");
    sph::require_positive(p.speed_of_sound, "params->speed_of_sound");
    update_params(world, [&](sph::RuntimeParams& r) { r.tait_sound_speed = p.speed_of_sound; });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_tait_params(const sph_world* world, sph_tait_params* out) {
  return sph::guarded("sph_world_get_tait_params", sph::context_of(world), [&] {
    sph::require_world(world);
    require_feature(has_tait(world), "SPH_EOS_TAIT");
    sph_tait_params p;
    std::memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.speed_of_sound = world->world->params().tait_sound_speed;
    sph::write_output_struct(out, p, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_spring_params_init_sized(sph_spring_params* params, uint32_t size) {
  return sph::init_user_struct("sph_spring_params_init", "params", params, size, [](sph_spring_params& d) {
    const sph::RuntimeParams defaults;
    d.stiffness = defaults.spring_stiffness;
    d.link_radius = defaults.spring_link_radius;
    d.yield_ratio = defaults.spring_yield_ratio;
    d.plasticity = defaults.spring_plasticity;
    d.damping = defaults.spring_damping;
  });
}

SPH_API sph_result SPH_CALL sph_world_set_spring_params(sph_world* world, const sph_spring_params* params) {
  return sph::guarded("sph_world_set_spring_params", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_feature(has_springs(world), "SPH_FEATURE_SPRINGS");
    const sph_spring_params p = sph::read_user_struct(params, "params");
    sph::require_non_negative(p.stiffness, "params->stiffness");
    sph::require_non_negative(p.link_radius, "params->link_radius");
    const float h = world->world->config().kernel_radius;
    if (p.link_radius > h)
      throw Error(Status::InvalidArgument, "params->link_radius: " + sph::describe(p.link_radius) +
                                               " m is above the kernel radius " + sph::describe(h) + " m");
    sph::require_non_negative(p.yield_ratio, "params->yield_ratio");
    if (p.yield_ratio > 1.0f)
      throw Error(Status::InvalidArgument,
                  "params->yield_ratio: must be in [0, 1], got " + sph::describe(p.yield_ratio));
    sph::require_non_negative(p.plasticity, "params->plasticity");
    sph::require_non_negative(p.damping, "params->damping");
    sph::require_zero(p.reserved0, "params->reserved0");
    update_params(world, [&](sph::RuntimeParams& r) {
      r.spring_stiffness = p.stiffness;
      r.spring_link_radius = p.link_radius;
      r.spring_yield_ratio = p.yield_ratio;
      r.spring_plasticity = p.plasticity;
      r.spring_damping = p.damping;
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_spring_params(const sph_world* world, sph_spring_params* out) {
  return sph::guarded("sph_world_get_spring_params", sph::context_of(world), [&] {
    sph::require_world(world);
    require_feature(has_springs(world), "SPH_FEATURE_SPRINGS");
    const sph::RuntimeParams& r = world->world->params();
    sph_spring_params p;
    std::memset(&p, 0, sizeof p);
    p.struct_size = sizeof p;
    p.stiffness = r.spring_stiffness;
    p.link_radius = r.spring_link_radius;
    p.yield_ratio = r.spring_yield_ratio;
    p.plasticity = r.spring_plasticity;
    p.damping = r.spring_damping;
    sph::write_output_struct(out, p, "out");
    return SPH_OK;
  });
}

}  // extern "C"
