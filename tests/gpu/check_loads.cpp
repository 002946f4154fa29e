// SPDX-License-Identifier: MIT
// Loads on colliders on the GPU (issue 17): a column collapsing in a tank with a fixed box in
// its way, on the CUDA backend:
//   - two runs give bitwise-identical loads (the fixed-order block sums) and states; the graph
//     frame and the stream driver agree bit for bit;
//   - the loads pass leaves the trajectory alone: a world with SPH_FEATURE_COLLIDER_LOADS steps
//     to the bits of one without;
//   - CPU against GPU after one frame of 1/60 s: each collider's force within 1e-3 of the
//     fluid's weight (the sums differ only in float rounding and summation order there);
//   - momentum balance on the device over 10 frames: fluid dP + colliders' J = M g T within 1 %.
// With and without SPH_FEATURE_BOUNDARY_DENSITY, symplectic Euler and RK4, and DFSPH (its loads add
// the contact clamp's impulses, collider_loads.h) with and without the boundary density.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "gpu_check.h"

using namespace gpu_check;

namespace {

struct LoadsRun {
  State state;
  std::vector<State> frame_states;        // after every frame, to name the first that differs
  std::vector<uint32_t> substeps;         // of every frame
  std::vector<sph_collider_loads> loads;  // per collider, the last frame's
  double momentum[3] = {0, 0, 0}, impulse[3] = {0, 0, 0}, start[3] = {0, 0, 0}, time = 0, mass = 0;
};

void momentum(const sph_world* w, float m, double out[3]) {
  uint32_t n = 0;
  require_ok(sph_world_get_particle_count(w, &n), "count");
  std::vector<float> v(3 * static_cast<size_t>(n) + 3);
  uint32_t count = 0;
  require_ok(support_read(w, SPH_ATTRIBUTE_VELOCITY, v.data(), n, &count), "velocities");
  out[0] = out[1] = out[2] = 0.0;
  for (uint32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) out[k] += static_cast<double>(m) * v[3 * i + k];
}

LoadsRun run(sph_backend backend, uint32_t features, sph_integrator integrator, int frames,
             sph_solver solver) {
  LoadsRun r;
  sph_context* context = make_context(backend);
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 20000;
  def.particle_spacing = 0.02f;
  def.features = features;
  def.integrator = integrator;
  def.solver = solver;
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &def, &world), "sph_world_create");
  const TankWithBox scene = add_tank_with_box(context, world, 0.01);
  const std::vector<sph_collider_id> ids = {scene.tank_collider, scene.box_collider};
  float m = 0.0f;
  require_ok(sph_world_get_particle_mass(world, &m), "mass");
  momentum(world, m, r.start);
  const bool loads = (features & SPH_FEATURE_COLLIDER_LOADS) != 0;
  for (int f = 0; f < frames; ++f) {
    require_ok(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");
    r.frame_states.push_back(read_state(world));
    r.substeps.push_back(get_stats(world).substeps);
    if (!loads) continue;
    r.loads.clear();
    for (sph_collider_id id : ids) {
      sph_collider_loads l;
      sph_collider_loads_init(&l);
      require_ok(sph_collider_get_loads(world, id, &l), "sph_collider_get_loads");
      r.loads.push_back(l);
      r.impulse[0] += l.force.x * l.frame_time;
      r.impulse[1] += l.force.y * l.frame_time;
      r.impulse[2] += l.force.z * l.frame_time;
    }
    r.time += r.loads[0].frame_time;
  }
  momentum(world, m, r.momentum);
  uint32_t n = 0;
  require_ok(sph_world_get_particle_count(world, &n), "count");
  r.mass = static_cast<double>(m) * n;
  r.state = read_state(world);
  sph_world_destroy(world);
  sph_sdf_destroy(scene.tank);
  sph_sdf_destroy(scene.box);
  sph_context_destroy(context);
  return r;
}

bool same_loads(const LoadsRun& a, const LoadsRun& b) {
  if (a.loads.size() != b.loads.size()) return false;
  for (size_t k = 0; k < a.loads.size(); ++k)
    if (std::memcmp(&a.loads[k], &b.loads[k], sizeof(sph_collider_loads)) != 0) return false;
  return true;
}

void check(uint32_t extra, sph_integrator integrator, const char* label,
           sph_solver solver = SPH_SOLVER_WCSPH) {
  const uint32_t features = SPH_FEATURE_COLLIDER_LOADS | extra;
  const int frames = integrator == SPH_INTEGRATOR_RK4 ? 4 : 10;
  const LoadsRun a = run(SPH_BACKEND_CUDA, features, integrator, frames, solver);
  const LoadsRun b = run(SPH_BACKEND_CUDA, features, integrator, frames, solver);
  char name[160];
  std::snprintf(name, sizeof name, "loads/determinism/%s", label);
  report(same_loads(a, b) && states_identical(a.state, b.state), name, "two GPU runs: loads and states %s",
         same_loads(a, b) && states_identical(a.state, b.state) ? "bitwise identical" : "DIFFER");

  context_tuning().stream_frames = true;
  const LoadsRun s = run(SPH_BACKEND_CUDA, features, integrator, frames, solver);
  context_tuning().stream_frames = false;
  std::snprintf(name, sizeof name, "loads/graph_vs_stream/%s", label);
  report(same_loads(a, s) && states_identical(a.state, s.state), name,
         "graph frame against stream driver: %s",
         same_loads(a, s) && states_identical(a.state, s.state) ? "bitwise identical" : "DIFFERENT");

  const LoadsRun off = run(SPH_BACKEND_CUDA, extra, integrator, frames, solver);
  std::snprintf(name, sizeof name, "loads/trajectory_unchanged/%s", label);
  size_t first = 0;
  while (first < a.frame_states.size() && states_identical(a.frame_states[first], off.frame_states[first]))
    ++first;
  std::string where = "bitwise identical";
  if (first < a.frame_states.size()) {
    const State &x = a.frame_states[first], &y = off.frame_states[first];
    where = "DIFFER from frame " + std::to_string(first + 1) + " (substeps " +
            std::to_string(a.substeps[first]) + " with loads, " + std::to_string(off.substeps[first]) +
            " without; positions " + (bitwise_equal(x.position, y.position) ? "same" : "differ") +
            ", velocities " + (bitwise_equal(x.velocity, y.velocity) ? "same" : "differ") + ", densities " +
            (bitwise_equal(x.density, y.density) ? "same" : "differ") + ")";
  }
  report(states_identical(a.state, off.state), name, "with loads against without: states %s", where.c_str());

  const double weight = a.mass * 9.81;
  const double residual[3] = {a.momentum[0] - a.start[0] + a.impulse[0],
                              a.momentum[1] - a.start[1] + a.impulse[1] + weight * a.time,
                              a.momentum[2] - a.start[2] + a.impulse[2]};
  const double error =
      std::sqrt(residual[0] * residual[0] + residual[1] * residual[1] + residual[2] * residual[2]) /
      (weight * a.time);
  std::snprintf(name, sizeof name, "loads/momentum_balance/%s", label);
  report(error <= 0.01, name, "fluid dP + colliders' J - M g T over %.3f s: %.3g of M g T", a.time, error);

  const LoadsRun gpu = run(SPH_BACKEND_CUDA, features, integrator, 1, solver);
  const LoadsRun cpu = run(SPH_BACKEND_CPU, features, integrator, 1, solver);
  double worst = 0.0;
  for (size_t k = 0; k < gpu.loads.size(); ++k) {
    const double d[3] = {gpu.loads[k].force.x - cpu.loads[k].force.x,
                         gpu.loads[k].force.y - cpu.loads[k].force.y,
                         gpu.loads[k].force.z - cpu.loads[k].force.z};
    worst = std::fmax(worst, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / weight);
  }
  std::snprintf(name, sizeof name, "loads/cpu_vs_gpu/%s", label);
  report(worst <= 1e-3, name, "after one frame, the largest force difference is %.3g of the weight", worst);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  check(0u, SPH_INTEGRATOR_SYMPLECTIC_EULER, "contacts_euler");
  check(SPH_FEATURE_BOUNDARY_DENSITY, SPH_INTEGRATOR_SYMPLECTIC_EULER, "boundary_density_euler");
  check(SPH_FEATURE_BOUNDARY_DENSITY, SPH_INTEGRATOR_RK4, "boundary_density_rk4");
  check(0u, SPH_INTEGRATOR_SYMPLECTIC_EULER, "contacts_dfsph", SPH_SOLVER_DFSPH);
  check(SPH_FEATURE_BOUNDARY_DENSITY, SPH_INTEGRATOR_SYMPLECTIC_EULER, "boundary_density_dfsph",
        SPH_SOLVER_DFSPH);
  return finish();
}
