// SPDX-License-Identifier: MIT
// Probes and gauges on the GPU (issue 17 item 2): a column collapsing in a tank, watched by
// points (every substep and every frame) and a gauge, on the CUDA backend:
//   - two runs give bitwise-identical readings (fixed-order sums); the graph frame and the stream
//     driver agree bit for bit;
//   - probes leave the trajectory alone: a world with probes steps to the bits of one without;
//   - samples: an EVERY_SUBSTEP probe has as many samples as the step had substeps;
//   - CPU against GPU after one frame of 1/60 s (the states differ only in float rounding there):
//     densities within 1e-3 of rho0, pressures within 1e-3 of rho0 g H, velocities within 1e-3
//     of sqrt(g H), the gauge's height within 1e-3 of H.
// Symplectic Euler, RK4, and DFSPH (whose probes sample the substep's start after its solves).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "gpu_check.h"

using namespace gpu_check;

namespace {

constexpr double kColumnHeight = 0.3;

struct ProbesRun {
  State state;
  std::vector<sph_probe_reading> readings;  // the last frame's, per probe
  uint32_t substeps = 0;
};

ProbesRun run(sph_backend backend, sph_integrator integrator, int frames, bool probes, sph_solver solver) {
  ProbesRun r;
  sph_context* context = make_context(backend);
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 20000;
  def.particle_spacing = 0.02f;
  def.integrator = integrator;
  def.solver = solver;
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &def, &world), "sph_world_create");
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {0.6, 0.4, 0.2};
  sph_sdf* tank = nullptr;
  require_ok(support_tank_between(context, world, lo, hi, 0.01, 0.0f, &tank, nullptr), "tank");
  sph_fill_box_desc column;
  sph_fill_box_desc_init(&column);
  column.max = sph_vec3{0.2f, static_cast<float>(kColumnHeight), 0.2f};
  require_ok(sph_world_fill_box(world, &column, nullptr), "fill");
  std::vector<sph_probe_id> ids;
  if (probes) {
    const float points[3][3] = {{0.1f, 0.05f, 0.1f}, {0.15f, 0.2f, 0.05f}, {0.3f, 0.02f, 0.1f}};
    for (int k = 0; k < 3; ++k) {
      sph_probe_def p;
      sph_probe_def_init(&p);
      p.position = sph_vec3{points[k][0], points[k][1], points[k][2]};
      p.sampling = k == 0 ? SPH_PROBE_EVERY_SUBSTEP : SPH_PROBE_EVERY_FRAME;
      ids.emplace_back();
      require_ok(sph_probe_create(world, &p, &ids.back()), "sph_probe_create");
    }
    sph_probe_def g;
    sph_probe_def_init(&g);
    g.kind = SPH_PROBE_GAUGE;
    g.position = sph_vec3{0.1f, -0.05f, 0.1f};
    g.length = 0.5f;
    ids.emplace_back();
    require_ok(sph_probe_create(world, &g, &ids.back()), "sph_probe_create (gauge)");
  }
  for (int f = 0; f < frames; ++f) require_ok(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");
  for (sph_probe_id id : ids) {
    sph_probe_reading reading;
    sph_probe_reading_init(&reading);
    require_ok(sph_probe_get_reading(world, id, &reading), "sph_probe_get_reading");
    r.readings.push_back(reading);
  }
  sph_stats stats;
  sph_stats_init(&stats);
  require_ok(sph_world_get_stats(world, &stats), "stats");
  r.substeps = stats.substeps;
  r.state = read_state(world);
  sph_world_destroy(world);
  sph_sdf_destroy(tank);
  sph_context_destroy(context);
  return r;
}

bool same_readings(const ProbesRun& a, const ProbesRun& b) {
  if (a.readings.size() != b.readings.size()) return false;
  for (size_t k = 0; k < a.readings.size(); ++k)
    if (std::memcmp(&a.readings[k], &b.readings[k], sizeof(sph_probe_reading)) != 0) return false;
  return true;
}

void check(sph_integrator integrator, const char* label, sph_solver solver = SPH_SOLVER_WCSPH) {
  const int frames = 6;
  const ProbesRun a = run(SPH_BACKEND_CUDA, integrator, frames, true, solver);
  const ProbesRun b = run(SPH_BACKEND_CUDA, integrator, frames, true, solver);
  char name[160];
  const bool same = same_readings(a, b) && states_identical(a.state, b.state);
  std::snprintf(name, sizeof name, "probes/determinism/%s", label);
  report(same, name, "two GPU runs: readings and states %s", same ? "bitwise identical" : "DIFFER");

  context_tuning().stream_frames = true;
  const ProbesRun s = run(SPH_BACKEND_CUDA, integrator, frames, true, solver);
  context_tuning().stream_frames = false;
  const bool stream_same = same_readings(a, s) && states_identical(a.state, s.state);
  std::snprintf(name, sizeof name, "probes/graph_vs_stream/%s", label);
  report(stream_same, name, "graph frame against stream driver: %s",
         stream_same ? "bitwise identical" : "DIFFERENT");

  const ProbesRun off = run(SPH_BACKEND_CUDA, integrator, frames, false, solver);
  std::snprintf(name, sizeof name, "probes/trajectory_unchanged/%s", label);
  report(states_identical(a.state, off.state), name, "with probes against without: states %s",
         states_identical(a.state, off.state) ? "bitwise identical" : "DIFFER");

  std::snprintf(name, sizeof name, "probes/samples/%s", label);
  report(a.readings[0].samples == a.substeps && a.readings[1].samples == 1, name,
         "EVERY_SUBSTEP: %u samples of %u substeps; EVERY_FRAME: %u", a.readings[0].samples, a.substeps,
         a.readings[1].samples);

  const ProbesRun gpu = run(SPH_BACKEND_CUDA, integrator, 1, true, solver);
  const ProbesRun cpu = run(SPH_BACKEND_CPU, integrator, 1, true, solver);
  const double rho0 = 1000.0, pressure_scale = rho0 * 9.81 * kColumnHeight,
               speed = std::sqrt(9.81 * kColumnHeight);
  double worst = 0.0;
  for (size_t k = 0; k < gpu.readings.size(); ++k) {
    const sph_probe_reading& g = gpu.readings[k];
    const sph_probe_reading& c = cpu.readings[k];
    worst = std::fmax(worst, std::fabs(g.density - c.density) / rho0);
    worst = std::fmax(worst, std::fabs(g.pressure - c.pressure) / pressure_scale);
    worst = std::fmax(worst, std::fabs(g.velocity.x - c.velocity.x) / speed);
    worst = std::fmax(worst, std::fabs(g.velocity.y - c.velocity.y) / speed);
    worst = std::fmax(worst, std::fabs(g.velocity.z - c.velocity.z) / speed);
    worst = std::fmax(worst, std::fabs(g.water_height - c.water_height) / kColumnHeight);
  }
  std::snprintf(name, sizeof name, "probes/cpu_vs_gpu/%s", label);
  report(worst <= 1e-3, name, "after one frame, the largest reading difference is %.3g of its scale", worst);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  check(SPH_INTEGRATOR_SYMPLECTIC_EULER, "euler");
  check(SPH_INTEGRATOR_RK4, "rk4");
  check(SPH_INTEGRATOR_SYMPLECTIC_EULER, "dfsph", SPH_SOLVER_DFSPH);
  return finish();
}
