// SPDX-License-Identifier: MIT
// Bitwise determinism: two GPU runs of the same scene give identical arrays (compared by id)
// and identical statistics; the graph path and the stream fallback agree bit for bit; two
// worlds stepped at once from two threads give the same bits as one at a time.
#include <cuda_runtime.h>

#include <cstdlib>
#include <thread>

#include "gpu_check.h"

using namespace gpu_check;

namespace {

struct Run {
  State state;
  sph_stats stats;
};

Run run(const SceneSpec& spec, int frames, float frame_dt) {
  Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
  for (int f = 0; f < frames; ++f) require_ok(sph_world_step(l.world, frame_dt), "sph_world_step");
  Run r{read_state(l.world), get_stats(l.world)};
  l.destroy();
  return r;
}

bool same_stats(const sph_stats& a, const sph_stats& b) {
  return a.substeps == b.substeps && a.max_speed == b.max_speed && a.density_min == b.density_min &&
         a.density_mean == b.density_mean && a.density_max == b.density_max &&
         a.neighbors_mean == b.neighbors_mean && a.neighbors_max == b.neighbors_max && a.dt_min == b.dt_min &&
         a.dt_max == b.dt_max && a.frame_time == b.frame_time;
}

void twice(const SceneSpec& spec, int frames, float frame_dt) {
  const Run a = run(spec, frames, frame_dt);
  const Run b = run(spec, frames, frame_dt);
  const std::string name = std::string("determinism/") + spec.name;
  report(states_identical(a.state, b.state) && same_stats(a.stats, b.stats), name.c_str(),
         "%u particles, %d frames, %u substeps in the last: positions, velocities, densities, pressures, ids "
         "and statistics %s",
         a.state.count, frames, a.stats.substeps,
         states_identical(a.state, b.state) && same_stats(a.stats, b.stats) ? "bitwise identical" : "DIFFER");

  context_tuning().stream_frames = true;
  const Run c = run(spec, frames, frame_dt);
  context_tuning().stream_frames = false;
  const std::string name2 = std::string("graph_vs_stream/") + spec.name;
  report(
      states_identical(a.state, c.state) && same_stats(a.stats, c.stats), name2.c_str(),
      "the CUDA-graph frame and the stream fallback give %s results",
      states_identical(a.state, c.state) && same_stats(a.stats, c.stats) ? "bitwise identical" : "DIFFERENT");

  // The block sizes of sph_context_def only change how particles are grouped into blocks: each
  // particle's gather and every reduction (max by integer bits) are the same.
  context_tuning().density_block = 256;
  context_tuning().force_block = 64;
  const Run d = run(spec, frames, frame_dt);
  context_tuning().density_block = 0;
  context_tuning().force_block = 0;
  const std::string name3 = std::string("block_sizes/") + spec.name;
  report(
      states_identical(a.state, d.state) && same_stats(a.stats, d.stats), name3.c_str(),
      "density blocks of 256 and force blocks of 64 against the default 128: %s",
      states_identical(a.state, d.state) && same_stats(a.stats, d.stats) ? "bitwise identical" : "DIFFERENT");
}

void concurrent(const SceneSpec& spec, int frames, float frame_dt) {
  const Run alone = run(spec, frames, frame_dt);
  Run results[2];
  std::thread t0([&] { results[0] = run(spec, frames, frame_dt); });
  std::thread t1([&] { results[1] = run(spec, frames, frame_dt); });
  t0.join();
  t1.join();
  const bool ok =
      states_identical(alone.state, results[0].state) && states_identical(alone.state, results[1].state);
  report(ok, "determinism/two_worlds_two_threads",
         "two worlds stepped concurrently on two threads %s one alone", ok ? "match" : "DO NOT match");
}

}  // namespace

int main() {
  exit_if_no_cuda();
  SceneSpec moving;
  moving.name = "moving_sphere_euler";
  moving.radius = 0.4f;  // about 47k particles
  moving.random_speed = 0.1f;
  moving.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  twice(moving, 5, 0.04f);

  SceneSpec fast = moving;
  fast.name = "fast_sphere_adaptive_dt_euler";
  fast.random_speed = 0.5f;
  fast.drift = sph_vec3{0.0f, 0.0f, -6.0f};
  fast.step_factor = 0.1f;
  twice(fast, 3, 0.01f);

  SceneSpec rk4 = moving;
  rk4.name = "moving_sphere_rk4";
  rk4.integrator = SPH_INTEGRATOR_RK4;
  twice(rk4, 2, 0.04f);

  SceneSpec options = moving;
  options.name = "moving_sphere_all_options_euler";
  options.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  options.viscosity_method = SPH_VISCOSITY_CLAVET;
  options.step_limits = SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE;
  twice(options, 3, 0.02f);

  SceneSpec springs = moving;
  springs.name = "moving_sphere_springs_euler";
  springs.features = SPH_FEATURE_SPRINGS;
  twice(springs, 3, 0.02f);

  // Eight threads per particle in the neighbour passes (lane groups, cuda/force_gather.cuh;
  // sph_context_def.cuda_particle_lanes): the groups' fixed-order sums keep every run's bits
  // (twice: two runs, graph against stream, other block sizes).
  SceneSpec lanes = moving;
  lanes.name = "moving_sphere_euler_lanes8";
  context_tuning().particle_lanes = 8;
  twice(lanes, 5, 0.04f);
  {
    // The field reaches the kernels: eight lanes sum in another order than one, so some bits
    // differ after 200 substeps of 47k moving particles.
    context_tuning().particle_lanes = 8;
    const Run eight = run(lanes, 5, 0.04f);
    context_tuning().particle_lanes = 1;
    const Run one = run(lanes, 5, 0.04f);
    const bool same = states_identical(eight.state, one.state);
    report(!same, "lane_groups/moving_sphere_euler", "eight lanes per particle against one: %s",
           same ? "IDENTICAL (the field did not reach the kernels)" : "different last bits, as expected");
  }
  {
    // The library's choice (cuda_particle_lanes 0) is the fewest lanes, up to 4, with which the
    // particles fill the device's resident thread slots (lanes_per_particle): here the same
    // bits as that explicit count, and on a device of 270k slots (an H200) 4 lanes for 47k.
    int sms = 0, per_sm = 0;
    cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, 0);
    cudaDeviceGetAttribute(&per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, 0);
    context_tuning().particle_lanes = 0;
    const Run chosen = run(lanes, 5, 0.04f);
    const uint64_t slots = static_cast<uint64_t>(sms) * static_cast<uint64_t>(per_sm);
    uint32_t expected = 1;
    while (expected < 4 && static_cast<uint64_t>(chosen.stats.particle_count) * expected < slots)
      expected *= 2;
    context_tuning().particle_lanes = expected;
    const Run explicit_count = run(lanes, 5, 0.04f);
    report(states_identical(chosen.state, explicit_count.state), "lane_groups/default_choice",
           "%u particles, %llu thread slots: the library's choice computes the bits of %u lanes",
           chosen.stats.particle_count, static_cast<unsigned long long>(slots), expected);
  }
  SceneSpec lanes_options = options;
  lanes_options.name = "moving_sphere_all_options_euler_lanes8";
  context_tuning().particle_lanes = 8;
  twice(lanes_options, 3, 0.02f);
  SceneSpec lanes_rk4 = rk4;
  lanes_rk4.name = "moving_sphere_rk4_lanes4";
  context_tuning().particle_lanes = 4;
  twice(lanes_rk4, 2, 0.04f);
  context_tuning() = ContextTuning{};

  SceneSpec small = moving;
  small.radius = 0.25f;
  concurrent(small, 3, 0.02f);
  return finish();
}
