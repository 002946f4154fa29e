// SPDX-License-Identifier: MIT
// Checkpoints on the CUDA backend (docs/checkpoint.md): a CUDA world saved mid-run and loaded
// into a new CUDA world continues bit for bit, on the CUDA-graph path and on the stream
// fallback, with and without a scene (collider, sink, force field); restoring in place does the
// same; a CPU checkpoint loads into a CUDA world and agrees with the CPU continuing to float
// tolerance (1e-4 relative in positions after one frame, the parity check's limit: the backends
// sum in different orders, so bitwise equality is promised only within one backend).
#include <cstdlib>

#include "gpu_check.h"

using namespace gpu_check;

namespace {

constexpr float kFrame = 0.01f;

std::vector<uint8_t> save(const sph_world* world) {
  uint64_t size = 0;
  require_ok(sph_world_save(world, nullptr, 0, &size), "sph_world_save (size)");
  std::vector<uint8_t> bytes(size);
  require_ok(sph_world_save(world, bytes.data(), size, &size), "sph_world_save");
  return bytes;
}

// Every attribute in the world's storage order (sinks leave gaps in the ids, and the storage
// order is part of what a checkpoint must reproduce).
State raw_state(const sph_world* world) { return read_attributes(world, false); }

// A tank-less scene piece: a sphere collider the drop falls onto, an outside-bounds sink and a
// vortex, so the sink path (stream) and the scene upload run after the load too.
void add_scene(sph_context* context, sph_world* world) {
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.15f;
  shape.voxel_size = 0.02f;
  sph_sdf* ball = nullptr;
  require_ok(sph_sdf_create_shape(context, &shape, &ball), "sph_sdf_create_shape");
  sph_collider_def collider;
  sph_collider_def_init(&collider);
  collider.sdf = ball;
  collider.transform.position.y = -0.45f;
  sph_collider_id cid;
  require_ok(sph_collider_create(world, &collider, &cid), "sph_collider_create");
  sph_sink_def sink;
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min = sph_vec3{-0.5f, -0.42f, -0.5f};
  sink.bounds_max = sph_vec3{0.5f, 0.5f, 0.5f};
  sph_sink_id sid;
  require_ok(sph_sink_create(world, &sink, &sid), "sph_sink_create");
  sph_force_field_def field;
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  field.vector = sph_vec3{0.0f, 1.0f, 0.0f};
  field.strength = 3.0f;
  sph_force_field_id fid;
  require_ok(sph_force_field_create(world, &field, &fid), "sph_force_field_create");
  sph_sdf_destroy(ball);
}

// Saves a CUDA world after `before` frames; the original and a loaded copy (and the original
// restored in place) then step `after` frames and must agree bit for bit.
void continuation(const SceneSpec& spec, bool scene, int before, int after, const char* mode) {
  Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
  if (scene) add_scene(l.context, l.world);
  for (int f = 0; f < before; ++f) require_ok(sph_world_step(l.world, kFrame), "sph_world_step");
  const std::vector<uint8_t> bytes = save(l.world);
  for (int f = 0; f < after; ++f) require_ok(sph_world_step(l.world, kFrame), "sph_world_step");
  const State expected = raw_state(l.world);
  const sph_stats expected_stats = get_stats(l.world);

  sph_world* loaded = nullptr;
  require_ok(sph_world_load(l.context, bytes.data(), bytes.size(), &loaded), "sph_world_load");
  for (int f = 0; f < after; ++f) require_ok(sph_world_step(loaded, kFrame), "sph_world_step (loaded)");
  const State got = raw_state(loaded);
  const sph_stats got_stats = get_stats(loaded);

  require_ok(sph_world_restore(l.world, bytes.data(), bytes.size()), "sph_world_restore");
  for (int f = 0; f < after; ++f) require_ok(sph_world_step(l.world, kFrame), "sph_world_step (restored)");
  const State restored = raw_state(l.world);

  const bool same_stats = got_stats.substeps == expected_stats.substeps &&
                          got_stats.max_speed == expected_stats.max_speed &&
                          got_stats.density_mean == expected_stats.density_mean &&
                          got_stats.simulated_time == expected_stats.simulated_time;
  const bool ok = states_identical(expected, got) && states_identical(expected, restored) && same_stats;
  const std::string name = std::string("checkpoint/") + spec.name + (scene ? "_scene/" : "/") + mode;
  report(ok, name.c_str(),
         "%u particles (%u after), %zu-byte checkpoint after %d frames, %d frames on: loaded and restored "
         "worlds %s",
         l.count, expected.count, bytes.size(), before, after,
         ok ? "bitwise identical (storage order, stats)" : "DIFFER");
  sph_world_destroy(loaded);
  l.destroy();
}

// A CPU checkpoint loaded into a CUDA world: one frame on each backend, positions within 1e-4
// of the drop's extent (the parity limit).
void cpu_to_cuda(const SceneSpec& spec) {
  Loaded cpu = load_scene(SPH_BACKEND_CPU, spec);
  require_ok(sph_world_step(cpu.world, kFrame), "sph_world_step (cpu)");
  const std::vector<uint8_t> bytes = save(cpu.world);
  require_ok(sph_world_step(cpu.world, kFrame), "sph_world_step (cpu)");
  const State expected = read_state(cpu.world);

  sph_context* cuda = make_context(SPH_BACKEND_CUDA);
  sph_world* loaded = nullptr;
  require_ok(sph_world_load(cuda, bytes.data(), bytes.size(), &loaded), "sph_world_load (cuda)");
  require_ok(sph_world_step(loaded, kFrame), "sph_world_step (cuda)");
  const State got = read_state(loaded);
  double dp = 0.0, scale = 0.0;
  for (size_t i = 0; i < expected.position.size(); ++i) {
    dp = std::max(dp, static_cast<double>(std::fabs(expected.position[i] - got.position[i])));
    scale = std::max(scale, static_cast<double>(std::fabs(expected.position[i])));
  }
  const bool ok = expected.count == got.count && dp <= 1e-4 * scale;
  report(ok, "checkpoint/cpu_to_cuda",
         "%u particles: max |x_cuda - x_cpu| = %.3g m, %.3g of max |x| (limit 1e-4)", got.count, dp,
         scale > 0 ? dp / scale : 0.0);
  sph_world_destroy(loaded);
  sph_context_destroy(cuda);
  cpu.destroy();
}

}  // namespace

int main() {
  exit_if_no_cuda();
  SceneSpec drop;
  drop.name = "falling_sphere_euler";
  drop.radius = 0.3f;  // about 20k particles
  drop.random_speed = 0.2f;
  drop.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  drop.step_factor = 0.1f;  // steps follow the fastest particle: the carried max speed matters
  drop.step_limits = SPH_STEP_LIMIT_FORCE;

  SceneSpec rk4 = drop;
  rk4.name = "falling_sphere_rk4_options";
  rk4.radius = 0.2f;
  rk4.integrator = SPH_INTEGRATOR_RK4;
  rk4.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  rk4.viscosity_method = SPH_VISCOSITY_CLAVET;

  for (int stream = 0; stream < 2; ++stream) {
    if (stream) context_tuning().stream_frames = true;
    const char* mode = stream ? "stream" : "graph";
    continuation(drop, false, 3, 3, mode);
    continuation(drop, true, 3, 3, mode);
    continuation(rk4, false, 2, 2, mode);
    if (stream) context_tuning().stream_frames = false;
  }
  SceneSpec small = drop;
  small.radius = 0.15f;
  cpu_to_cuda(small);
  return finish();
}
