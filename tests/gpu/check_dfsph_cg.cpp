// SPDX-License-Identifier: MIT
// DFSPH's density solve by conjugate gradients (sph_dfsph_params.linear_solver =
// SPH_DFSPH_CONJUGATE_GRADIENTS) on the CUDA backend against the CPU backend (issue 16): the
// Martin & Moyce dam break of tests/support/dam_break.c (its tank, column and parameters) at 12
// lattice layers across the column, 864 particles, the bound 0.1 %, one substep of 1 ms a frame
// (dt_max = the frame: the speed limit never binds below 4.8 ms here) for 60 substeps, so that the
// sph_stats of each frame are one substep's. The walls are the tank's collider, so the solve's
// contacts (binding at a cycle's start, held within it) are exercised from the first substep.
//   - iterations: each substep's density-solve iterations equal on both backends or within 1
//     (the CPU sums in exact arithmetic, the GPU in double block trees: a mean on the bound's
//     edge may stop one iteration apart);
//   - positions after 10 substeps within 1e-4 of max |x| and velocities within 1e-3 of max |v|,
//     the limits of every DFSPH case of gpu_check_parity (one frame of 10 substeps there): the
//     two backends' sums differ in rounding only, which those limits hold for Jacobi's solve;
//   - the achieved error within the bound on both, every substep, none capped;
//   - two runs through the CUDA graph and one through the stream driver give the same bits
//     (positions, velocities, densities, pressures, ids, and every substep's statistics).
#include <cstdlib>
#include <vector>

#include "gpu_check.h"

using namespace gpu_check;

namespace {

constexpr uint32_t kLayers = 12;     // across the column (slab: 6)
constexpr uint32_t kSubsteps = 60;   // 60 ms: the front has moved about half a column width
constexpr uint32_t kCompareAt = 10;  // gpu_check_parity's frame
constexpr float kDt = 1e-3f;         // s, one substep a frame
constexpr float kBound = 0.001f;     // the density solve's default bound
constexpr double kGravity = 9.81;

struct SubstepStats {
  uint32_t substeps, iterations, capped;
  float error;
};

struct Run {
  std::vector<SubstepStats> stats;
  State early, late;
  bool ok = true;
};

Run run(sph_backend backend, bool stream_frames) {
  context_tuning().stream_frames = stream_frames;
  sph_context* context = make_context(backend);
  context_tuning().stream_frames = false;
  // The geometry of dam_break_run (tests/support/dam_break.c), walls at the lattice's faces.
  const double a = 0.05715, step = a / kLayers;
  const uint32_t layers[3] = {kLayers, 2 * kLayers, 6};
  const double tank_min[3] = {0.0, 0.0, 0.0};
  const double tank_max[3] = {6.0 * a, 3.0 * a, step * layers[2]};
  float* positions = nullptr;
  uint32_t n = 0;
  require_ok(support_fcc_box(layers, step, nullptr, &positions, &n), "support_fcc_box");
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = n;
  def.particle_spacing = static_cast<float>(step * std::sqrt(2.0));
  def.solver = SPH_SOLVER_DFSPH;
  def.equation_of_state = SPH_EOS_IDEAL_GAS;
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &def, &world), "sph_world_create");
  sph_world_params params;
  sph_world_params_init(&params);
  params.gravity.y = static_cast<float>(-kGravity);
  params.viscosity = 0.05f;
  params.step_factor = 0.4f;
  params.dt_max = kDt;
  params.max_substeps = 100000;
  require_ok(sph_world_set_params(world, &params), "sph_world_set_params");
  sph_dfsph_params dfsph;
  sph_dfsph_params_init(&dfsph);
  dfsph.density_error = kBound;
  dfsph.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
  require_ok(sph_world_set_dfsph_params(world, &dfsph), "sph_world_set_dfsph_params(conjugate gradients)");
  sph_sdf* tank = nullptr;
  require_ok(support_tank_between(context, world, tank_min, tank_max, 0.5 * step, 0.0f, &tank, nullptr),
             "support_tank_between");
  require_ok(support_spawn(world, positions, nullptr, n), "support_spawn");
  std::free(positions);
  Run out;
  for (uint32_t s = 1; s <= kSubsteps; ++s) {
    require_ok(sph_world_step(world, kDt), "sph_world_step");
    const sph_stats st = get_stats(world);
    out.stats.push_back(
        SubstepStats{st.substeps, st.pressure_iterations, st.pressure_solves_capped, st.density_error_max});
    if (s == kCompareAt) out.early = read_state(world);
  }
  out.late = read_state(world);
  sph_world_destroy(world);
  sph_sdf_destroy(tank);
  sph_context_destroy(context);
  return out;
}

bool same_stats(const Run& a, const Run& b) {
  if (a.stats.size() != b.stats.size()) return false;
  for (size_t i = 0; i < a.stats.size(); ++i)
    if (a.stats[i].substeps != b.stats[i].substeps || a.stats[i].iterations != b.stats[i].iterations ||
        a.stats[i].capped != b.stats[i].capped ||
        std::memcmp(&a.stats[i].error, &b.stats[i].error, sizeof(float)) != 0)
      return false;
  return true;
}

double largest(const std::vector<float>& v) {
  double m = 0.0;
  for (size_t i = 0; i < v.size(); i += 3)
    m = std::max(m,
                 std::sqrt(double(v[i]) * v[i] + double(v[i + 1]) * v[i + 1] + double(v[i + 2]) * v[i + 2]));
  return m;
}

double largest_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0.0;
  for (size_t i = 0; i < a.size(); i += 3) {
    const double dx = double(a[i]) - b[i], dy = double(a[i + 1]) - b[i + 1], dz = double(a[i + 2]) - b[i + 2];
    m = std::max(m, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  return m;
}

// The solve within its bound on every substep, none capped, one substep a frame.
void check_bound(const Run& r, const char* backend) {
  uint32_t capped = 0, frames_off = 0, iterations = 0, most = 0;
  float worst = 0.0f;
  for (const SubstepStats& s : r.stats) {
    capped += s.capped;
    frames_off += s.substeps != 1 ? 1u : 0u;
    worst = std::max(worst, s.error);
    iterations += s.iterations;
    most = std::max(most, s.iterations);
  }
  const std::string name = std::string("dfsph cg: ") + backend + " within the bound";
  report(capped == 0 && frames_off == 0 && worst <= kBound, name.c_str(),
         "largest achieved error %.4f %% (bound %.2f %%), %u capped, %.2f iterations a substep (largest %u), "
         "%u frames not one substep",
         100.0 * worst, 100.0 * kBound, capped, double(iterations) / kSubsteps, most, frames_off);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  const Run cpu = run(SPH_BACKEND_CPU, false);
  const Run gpu = run(SPH_BACKEND_CUDA, false);
  const Run gpu_again = run(SPH_BACKEND_CUDA, false);
  const Run gpu_stream = run(SPH_BACKEND_CUDA, true);

  check_bound(cpu, "CPU");
  check_bound(gpu, "CUDA");

  uint32_t apart = 0, equal = 0, worst = 0, worst_at = 0;
  for (uint32_t s = 0; s < kSubsteps; ++s) {
    const uint32_t c = cpu.stats[s].iterations, g = gpu.stats[s].iterations;
    const uint32_t d = c > g ? c - g : g - c;
    equal += d == 0 ? 1u : 0u;
    apart += d > 1 ? 1u : 0u;
    if (d > worst) {
      worst = d;
      worst_at = s + 1;
    }
  }
  report(apart == 0, "dfsph cg: iterations per substep",
         "%u of %u substeps equal, %u more than 1 apart (largest %u, substep %u)", equal, kSubsteps, apart,
         worst, worst_at);

  const double scale = largest(cpu.early.position);
  const double dx = largest_difference(cpu.early.position, gpu.early.position);
  report(cpu.early.count == gpu.early.count && dx <= 1e-4 * scale, "dfsph cg: positions after 10 substeps",
         "max |x_gpu - x_cpu| = %.3g m, %.3g of max |x| = %.3g m (limit 1e-4)", dx, dx / scale, scale);
  const double vscale = std::max(largest(cpu.early.velocity), 1e-2);
  const double dv = largest_difference(cpu.early.velocity, gpu.early.velocity);
  report(dv <= 1e-3 * vscale, "dfsph cg: velocities after 10 substeps",
         "max |v_gpu - v_cpu| = %.3g m/s, %.3g of max |v| = %.3g m/s (limit 1e-3)", dv, dv / vscale, vscale);
  // Not a check: how far the two backends' rounding has carried the states apart by the end.
  std::printf("INFO dfsph cg: after %u substeps max |x_gpu - x_cpu| = %.3g m (%.3g of max |x|)\n", kSubsteps,
              largest_difference(cpu.late.position, gpu.late.position),
              largest_difference(cpu.late.position, gpu.late.position) / largest(cpu.late.position));

  report(states_identical(gpu.late, gpu_again.late) && states_identical(gpu.early, gpu_again.early) &&
             same_stats(gpu, gpu_again),
         "dfsph cg: two CUDA runs bitwise equal", "graph path, %u substeps", kSubsteps);
  report(states_identical(gpu.late, gpu_stream.late) && same_stats(gpu, gpu_stream),
         "dfsph cg: stream driver bitwise equal to the graph", "%u substeps", kSubsteps);
  return finish();
}
