// SPDX-License-Identifier: MIT
// CPU against GPU on the same scenes: after 10 substeps the positions (matched by id) agree
// within 1e-4 relative, and so do the density statistics. The scene cases (scene_parity.h) add
// colliders, force fields, sinks and sources, and check that three GPU runs agree bit for bit.
#include "gpu_check.h"
#include "scene_parity.h"

using namespace gpu_check;

namespace {

double rel(double a, double b) { return std::fabs(a - b) / std::max(std::fabs(b), 1e-30); }

void compare(const SceneSpec& spec, float frame_dt) {
  Loaded cpu = load_scene(SPH_BACKEND_CPU, spec);
  Loaded gpu = load_scene(SPH_BACKEND_CUDA, spec);
  const State start = read_state(cpu.world);
  require_ok(sph_world_step(cpu.world, frame_dt), "sph_world_step(CPU)");
  require_ok(sph_world_step(gpu.world, frame_dt), "sph_world_step(GPU)");
  const State c = read_state(cpu.world);
  const State g = read_state(gpu.world);
  const sph_stats cs = get_stats(cpu.world), gs = get_stats(gpu.world);
  std::string name = std::string("parity/") + spec.name;

  report(cs.substeps == gs.substeps && c.count == g.count, (name + "/substeps").c_str(),
         "%u particles, CPU %u substeps, GPU %u substeps (dt %.3g..%.3g s)", c.count, cs.substeps,
         gs.substeps, gs.dt_min, gs.dt_max);
  const double scale = max_abs(c.position);
  const double dp = max_diff(c.position, g.position);
  const double moved = max_diff(c.position, start.position);
  report(dp <= 1e-4 * scale, (name + "/positions").c_str(),
         "max |x_gpu - x_cpu| = %.3g m, %.3g relative to max |x| = %.3g m (limit 1e-4); %.3g of the largest "
         "displacement %.3g m",
         dp, dp / scale, scale, moved > 0 ? dp / moved : 0.0, moved);
  // Relative to the largest speed, but at least 1 cm/s: a sphere at rest has speeds of 1e-6 m/s,
  // pure rounding noise, and a relative comparison of noise means nothing.
  const double vscale = std::max(max_abs(c.velocity), 1e-2);
  const double dv = max_diff(c.velocity, g.velocity);
  report(dv <= 1e-3 * vscale, (name + "/velocities").c_str(),
         "max |v_gpu - v_cpu| = %.3g m/s, %.3g relative to max |v| = %.3g m/s (limit 1e-3)", dv, dv / vscale,
         vscale);
  const double e_min = rel(gs.density_min, cs.density_min), e_mean = rel(gs.density_mean, cs.density_mean),
               e_max = rel(gs.density_max, cs.density_max);
  report(
      e_min <= 1e-4 && e_mean <= 1e-4 && e_max <= 1e-4, (name + "/density_stats").c_str(),
      "min %.7g/%.7g mean %.7g/%.7g max %.7g/%.7g (GPU/CPU), largest relative difference %.3g (limit 1e-4)",
      gs.density_min, cs.density_min, gs.density_mean, cs.density_mean, gs.density_max, cs.density_max,
      std::max(e_min, std::max(e_mean, e_max)));
  report(gs.neighbors_max == cs.neighbors_max && rel(gs.neighbors_mean, cs.neighbors_mean) <= 1e-4,
         (name + "/neighbours").c_str(), "mean %.4f/%.4f max %u/%u (GPU/CPU)", gs.neighbors_mean,
         cs.neighbors_mean, gs.neighbors_max, cs.neighbors_max);
  report(std::fabs(gs.max_speed - cs.max_speed) <= 1e-3 * std::max(double(cs.max_speed), 1e-2),
         (name + "/max_speed").c_str(), "%.7g/%.7g m/s (GPU/CPU)", gs.max_speed, cs.max_speed);
  double dd = 0.0;
  for (uint32_t i = 0; i < c.count; ++i) dd = std::max(dd, rel(g.density[i], c.density[i]));
  report(dd <= 1e-4, (name + "/densities").c_str(), "largest relative difference per particle %.3g", dd);
  cpu.destroy();
  gpu.destroy();
}

}  // namespace

int main() {
  exit_if_no_cuda();
  SceneSpec rest;
  rest.name = "rest_sphere_euler";
  compare(rest, 0.010f);  // dt_max 1 ms: 10 substeps

  SceneSpec moving = rest;
  moving.name = "moving_sphere_gravity_euler";
  moving.random_speed = 0.1f;
  moving.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  compare(moving, 0.010f);

  SceneSpec fast = rest;
  fast.name = "fast_sphere_adaptive_dt_euler";
  fast.random_speed = 0.5f;
  fast.drift = sph_vec3{0.0f, 0.0f, -6.0f};
  fast.step_factor = 0.1f;  // dt = 0.1 h / v_max < dt_max: adaptive steps and a landing step
  compare(fast, 0.006f);

  SceneSpec rest_rk4 = rest;
  rest_rk4.name = "rest_sphere_rk4";
  rest_rk4.integrator = SPH_INTEGRATOR_RK4;
  compare(rest_rk4, 0.010f);

  SceneSpec moving_rk4 = moving;
  moving_rk4.name = "moving_sphere_gravity_rk4";
  moving_rk4.integrator = SPH_INTEGRATOR_RK4;
  compare(moving_rk4, 0.010f);

  // The physics options: each must give the CPU's result on the GPU too.
  SceneSpec tait = moving;
  tait.name = "options_tait_clavet_acoustic_force_limit_euler";
  tait.random_speed = 0.5f;
  tait.equation_of_state = SPH_EOS_TAIT;
  tait.viscosity_method = SPH_VISCOSITY_CLAVET;
  tait.step_limits = SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE;
  compare(tait, 0.010f);

  SceneSpec surface = moving;
  surface.name = "options_surface_tension_normalized_density_euler";
  surface.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  compare(surface, 0.010f);

  SceneSpec all_rk4 = tait;
  all_rk4.name = "options_all_rk4";
  all_rk4.integrator = SPH_INTEGRATOR_RK4;
  all_rk4.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  compare(all_rk4, 0.010f);

  SceneSpec springs = moving;
  springs.name = "options_springs_plastic_euler";
  springs.features = SPH_FEATURE_SPRINGS;
  compare(springs, 0.010f);
  SceneSpec springs_rk4 = springs;
  springs_rk4.name = "options_springs_plastic_rk4";
  springs_rk4.integrator = SPH_INTEGRATOR_RK4;
  compare(springs_rk4, 0.010f);

  // DFSPH (issue 16): its density and factor pass, both solves (the iteration counts must match:
  // the CPU sums each solve's error in storage order in double, the GPU in fixed-shape block
  // trees, and both stop on the same mean to within rounding) and the non-pressure terms.
  SceneSpec dfsph = moving;
  dfsph.name = "dfsph_moving_sphere_gravity_euler";
  dfsph.solver = SPH_SOLVER_DFSPH;
  compare(dfsph, 0.010f);
  SceneSpec dfsph_fast = fast;
  dfsph_fast.name = "dfsph_fast_sphere_adaptive_dt_euler";
  dfsph_fast.solver = SPH_SOLVER_DFSPH;
  compare(dfsph_fast, 0.006f);
  SceneSpec dfsph_options = moving;
  dfsph_options.name = "dfsph_options_surface_tension_clavet_springs_euler";
  dfsph_options.solver = SPH_SOLVER_DFSPH;
  dfsph_options.random_speed = 0.5f;
  dfsph_options.viscosity_method = SPH_VISCOSITY_CLAVET;
  dfsph_options.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_SPRINGS;
  compare(dfsph_options, 0.010f);

  // Lane groups (cuda/force_gather.cuh): 2, 4 or 8 threads per particle in the density and
  // weakly compressible force passes (sph_context_def.cuda_particle_lanes). Each sums the
  // candidates in another order than the CPU, within the same limits.
  for (uint32_t lanes : {2u, 4u, 8u}) {
    context_tuning().particle_lanes = lanes;
    const std::string suffix = "_lanes" + std::to_string(lanes);
    for (SceneSpec spec : {moving, moving_rk4, tait, surface, springs}) {
      const std::string name = spec.name + suffix;
      spec.name = name.c_str();
      compare(spec, 0.010f);
    }
  }
  context_tuning() = ContextTuning{};

  // Scenes: colliders, force fields, sinks and a source on both backends.
  run_scene_parity();
  return finish();
}
