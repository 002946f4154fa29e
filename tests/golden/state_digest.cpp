// SPDX-License-Identifier: MIT
// Prints a digest of the particle state after a fixed set of scenes, one line per scene, for one
// backend: `state_digest cpu` or `state_digest cuda`. Two builds whose digests match produce
// bit-for-bit the same particles (positions, velocities, densities, pressures, ids in storage
// order, removed ids in order, substep counts) on every scene: the check that a refactor changed
// no result (scripts/compare-state runs it against another revision). The scenes are the GPU
// parity cases (tests/gpu), which between them turn on every physics option, both integrators,
// colliders (static, moving, deforming), sinks, a source and every force-field kind.
// Uses only sph_c.h, so it builds against any revision of the library with the same API.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "../gpu/gpu_check.h"
#include "../gpu/scene_parity.h"

namespace {

using namespace gpu_check;

// FNV-1a over 64 bits: order-sensitive, so a permutation of the storage order changes it too.
struct Digest {
  uint64_t value = 1469598103934665603ull;
  void add(const void* data, size_t bytes) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t k = 0; k < bytes; ++k) {
      value ^= p[k];
      value *= 1099511628211ull;
    }
  }
  template <class T>
  void add(const std::vector<T>& v) {
    if (!v.empty()) add(v.data(), v.size() * sizeof(T));
  }
};

std::vector<float> copy_scalar(const sph_world* world, sph_attribute attribute, uint32_t n) {
  std::vector<float> out(n);
  uint32_t count = 0;
  require_ok(support_read(world, attribute, out.data(), n, &count), "copy");
  return out;
}

// Steps the scene and digests the state after every frame.
void digest_scene(sph_backend backend, const SceneHooks& h) {
  Loaded l = load_scene(backend, h.spec);
  if (h.build) h.build(l.context, l.world);
  Digest d;
  uint32_t substeps = 0;
  for (int f = 0; f < h.frames; ++f) {
    require_ok(sph_world_step(l.world, h.frame_dt), "sph_world_step");
    const RawState s = read_raw(l.world);
    d.add(&s.count, sizeof s.count);
    d.add(s.position);
    d.add(s.velocity);
    d.add(s.id);
    d.add(copy_scalar(l.world, SPH_ATTRIBUTE_DENSITY, s.count));
    d.add(copy_scalar(l.world, SPH_ATTRIBUTE_PRESSURE, s.count));
    d.add(removed_ids(l.world));
    const sph_stats st = get_stats(l.world);
    d.add(&st.substeps, sizeof st.substeps);
    d.add(&st.max_speed, sizeof st.max_speed);
    substeps += st.substeps;
  }
  std::printf("%-56s %016llx  (%u particles, %u substeps)\n", h.name,
              static_cast<unsigned long long>(d.value), l.count, substeps);
  std::fflush(stdout);
  l.destroy();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "cpu";
  sph_backend backend = SPH_BACKEND_CPU;
  if (which == "cuda") {
    exit_if_no_cuda();
    backend = SPH_BACKEND_CUDA;
  } else if (which != "cpu") {
    std::fprintf(stderr, "usage: state_digest [cpu|cuda]\n");
    return 2;
  }

  // The parity cases of tests/gpu/check_parity.cpp, two frames each.
  std::vector<SceneHooks> cases;
  auto add = [&](const char* name, const SceneSpec& spec, float frame_dt) {
    SceneHooks h{name, spec, nullptr};
    h.frame_dt = frame_dt;
    h.frames = 2;
    cases.push_back(h);
  };
  SceneSpec rest;
  add("rest_sphere_euler", rest, 0.010f);
  SceneSpec moving = rest;
  moving.random_speed = 0.1f;
  moving.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  add("moving_sphere_gravity_euler", moving, 0.010f);
  SceneSpec fast = rest;
  fast.random_speed = 0.5f;
  fast.drift = sph_vec3{0.0f, 0.0f, -6.0f};
  fast.step_factor = 0.1f;
  add("fast_sphere_adaptive_dt_euler", fast, 0.006f);
  SceneSpec rest_rk4 = rest;
  rest_rk4.integrator = SPH_INTEGRATOR_RK4;
  add("rest_sphere_rk4", rest_rk4, 0.010f);
  SceneSpec moving_rk4 = moving;
  moving_rk4.integrator = SPH_INTEGRATOR_RK4;
  add("moving_sphere_gravity_rk4", moving_rk4, 0.010f);
  SceneSpec tait = moving;
  tait.random_speed = 0.5f;
  tait.equation_of_state = SPH_EOS_TAIT;
  tait.viscosity_method = SPH_VISCOSITY_CLAVET;
  tait.step_limits = SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE;
  add("options_tait_clavet_acoustic_force_limit_euler", tait, 0.010f);
  SceneSpec surface = moving;
  surface.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  add("options_surface_tension_normalized_density_euler", surface, 0.010f);
  SceneSpec all_rk4 = tait;
  all_rk4.integrator = SPH_INTEGRATOR_RK4;
  all_rk4.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  add("options_all_rk4", all_rk4, 0.010f);
  SceneSpec springs = moving;
  springs.features = SPH_FEATURE_SPRINGS;
  add("options_springs_plastic_euler", springs, 0.010f);
  SceneSpec springs_rk4 = springs;
  springs_rk4.integrator = SPH_INTEGRATOR_RK4;
  add("options_springs_plastic_rk4", springs_rk4, 0.010f);
  SceneSpec dfsph = moving;
  dfsph.solver = SPH_SOLVER_DFSPH;
  add("dfsph_moving_sphere_gravity_euler", dfsph, 0.010f);
  SceneSpec dfsph_options = dfsph;
  dfsph_options.random_speed = 0.5f;
  dfsph_options.viscosity_method = SPH_VISCOSITY_CLAVET;
  dfsph_options.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_SPRINGS;
  add("dfsph_options_surface_tension_clavet_springs_euler", dfsph_options, 0.010f);

  // The scene cases of tests/gpu/scene_parity.h.
  SceneSpec base;
  base.random_speed = 0.1f;
  base.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  SceneHooks tank{"dam_break_tank_euler", base, build_tank};
  tank.spec.drift = sph_vec3{0.0f, -2.0f, 0.0f};
  cases.push_back(tank);
  SceneHooks tank_rk4 = tank;
  tank_rk4.name = "dam_break_tank_rk4";
  tank_rk4.spec.integrator = SPH_INTEGRATOR_RK4;
  cases.push_back(tank_rk4);
  cases.push_back(SceneHooks{"moving_paddle_floor_euler", base, build_paddle});
  cases.push_back(SceneHooks{"fast_turning_paddle_floor_euler", base, build_fast_paddle});
  SceneHooks deforming{"deforming_sdf_velocity_field_euler", base, build_deforming};
  deforming.spec.drift = sph_vec3{0.0f, -1.0f, 0.0f};
  cases.push_back(deforming);
  SceneHooks sinks{"sinks_region_and_bounds_euler", base, build_sinks};
  sinks.spec.drift = sph_vec3{1.0f, 0.0f, 0.0f};
  sinks.frames = 3;
  cases.push_back(sinks);
  SceneHooks sinks_rk4 = sinks;
  sinks_rk4.name = "sinks_region_and_bounds_rk4";
  sinks_rk4.spec.integrator = SPH_INTEGRATOR_RK4;
  cases.push_back(sinks_rk4);
  SceneHooks source{"continuous_source_euler", base, build_source};
  source.spec.spare_capacity = 4000;
  source.frames = 2;
  cases.push_back(source);
  cases.push_back(SceneHooks{"force_fields_all_kinds_euler", base, build_fields});
  SceneHooks spring_sinks = sinks;
  spring_sinks.name = "springs_sinks_euler";
  spring_sinks.spec.features = SPH_FEATURE_SPRINGS;
  cases.push_back(spring_sinks);
  SceneHooks spring_source = source;
  spring_source.name = "springs_continuous_source_euler";
  spring_source.spec.features = SPH_FEATURE_SPRINGS;
  cases.push_back(spring_source);
  SceneHooks dfsph_tank = tank;
  dfsph_tank.name = "dfsph_tank_euler";
  dfsph_tank.spec.solver = SPH_SOLVER_DFSPH;
  cases.push_back(dfsph_tank);
  SceneHooks dfsph_boundary_tank = dfsph_tank;
  dfsph_boundary_tank.name = "dfsph_boundary_density_tank_euler";
  dfsph_boundary_tank.spec.features = SPH_FEATURE_BOUNDARY_DENSITY;
  cases.push_back(dfsph_boundary_tank);

  for (const SceneHooks& h : cases) digest_scene(backend, h);
  return 0;
}
