// SPDX-License-Identifier: MIT
// Shared helpers of the GPU check programs (run by scripts/gpu-test on a machine with an
// NVIDIA GPU; never by ctest, so CI without a GPU does not see them). Each program prints one
// "PASS <name>: <detail>" or "FAIL <name>: <detail>" line per check and exits non-zero if any
// check failed, 77 if no CUDA device is present. The scenes come from tests/support (support.h).
#pragma once

#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sph_c.h"
#include "support.h"

namespace gpu_check {

inline int& failures() {
  static int count = 0;
  return count;
}

// Every PASS or FAIL line report() printed: a program that reached none of its checks fails
// (finish), rather than exiting 0 with nothing tested.
inline int& reports() {
  static int count = 0;
  return count;
}

inline void report(bool ok, const char* name, const char* format, ...) {
  char detail[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(detail, sizeof detail, format, args);
  va_end(args);
  std::printf("%s %s: %s\n", ok ? "PASS" : "FAIL", name, detail);
  std::fflush(stdout);
  ++reports();
  if (!ok) ++failures();
}

inline int finish() {
  if (reports() == 0) {
    std::printf("FAIL checks: the program reported no check\n");
    return 1;
  }
  return failures() == 0 ? 0 : 1;
}

// Stops the program with a FAIL line when an sph call does not return what it must.
inline void require(sph_result r, sph_result expected, const char* what) {
  if (r != expected) {
    std::printf("FAIL %s: returned %d (%s), expected %d; last error: %s\n", what, static_cast<int>(r),
                sph_result_string(r), static_cast<int>(expected), sph_get_last_error());
    std::exit(1);
  }
}
inline void require_ok(sph_result r, const char* what) {
  if (r < 0) require(r, SPH_OK, what);
}
// Stops the program with a FAIL line for a check that cannot run as it was asked to.
inline void fail_exit(const char* why) {
  std::printf("FAIL setup: %s\n", why);
  std::exit(1);
}

inline void exit_if_no_cuda() {
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  sph_context* context = nullptr;
  const sph_result r = sph_context_create(&def, &context);
  if (r == SPH_ERROR_UNSUPPORTED) {
    std::printf("SKIP: no CUDA device or no CUDA build (%s)\n", sph_get_last_error());
    std::exit(77);
  }
  require_ok(r, "sph_context_create(CUDA)");
  sph_context_destroy(context);
}

// The CUDA tuning of the contexts make_context creates (sph_context_def's cuda_* fields): the
// stream driver when stream_frames is set or SPH_CUDA_GRAPHS=0 is in the environment
// (scripts/gpu-test sets it; the library itself reads no environment), and the block sizes.
struct ContextTuning {
  bool stream_frames = false;
  uint32_t density_block = 0;  // 0: the library's default
  uint32_t force_block = 0;
  uint32_t particle_lanes = 0;  // cuda_particle_lanes; 0: the library's choice
  uint32_t dfsph_masks = 0;     // cuda_dfsph_masks: 0 masks, 1 off, 2 lists (check_dfsph_masks)
};
inline ContextTuning& context_tuning() {
  static ContextTuning tuning;
  return tuning;
}

// Written against the fields by template (a def without them is left alone), because
// scripts/compare-state builds this header against revisions from before the fields existed.
// Each returns whether the def had the field, so that a tuning a check asks for (a non-default
// value) fails loudly, rather than running untuned, when a field is renamed or missing.
template <class Def>
auto apply_context_tuning(Def& def, int) -> decltype(def.cuda_frames, def.cuda_density_block, bool()) {
  const char* graphs = std::getenv("SPH_CUDA_GRAPHS");
  const bool stream = context_tuning().stream_frames || (graphs && std::strcmp(graphs, "0") == 0);
  def.cuda_frames =
      static_cast<decltype(def.cuda_frames)>(stream ? 1 : 0);  // SPH_CUDA_FRAMES_STREAM : _GRAPH
  def.cuda_density_block = context_tuning().density_block;
  def.cuda_force_block = context_tuning().force_block;
  return true;
}
template <class Def>
bool apply_context_tuning(Def&, long) {
  return false;
}
template <class Def>
auto apply_particle_lanes(Def& def, int) -> decltype(def.cuda_particle_lanes, bool()) {
  def.cuda_particle_lanes = context_tuning().particle_lanes;
  return true;
}
template <class Def>
bool apply_particle_lanes(Def&, long) {
  return false;
}
template <class Def>
auto apply_dfsph_masks(Def& def, int) -> decltype(def.cuda_dfsph_masks, bool()) {
  def.cuda_dfsph_masks = context_tuning().dfsph_masks;
  return true;
}
template <class Def>
bool apply_dfsph_masks(Def&, long) {
  return false;
}

inline sph_context* make_context(sph_backend backend) {
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = backend;
  const ContextTuning& tuning = context_tuning();
  const bool asked_frames = tuning.stream_frames || tuning.density_block || tuning.force_block;
  if (!apply_context_tuning(def, 0) && asked_frames)
    fail_exit(
        "the check asks for cuda_frames / cuda_density_block / cuda_force_block, which this "
        "build's sph_context_def lacks");
  if (!apply_particle_lanes(def, 0) && tuning.particle_lanes)
    fail_exit("the check asks for cuda_particle_lanes, which this build's sph_context_def lacks");
  if (!apply_dfsph_masks(def, 0) && tuning.dfsph_masks)
    fail_exit("the check asks for cuda_dfsph_masks, which this build's sph_context_def lacks");
  sph_context* context = nullptr;
  require_ok(sph_context_create(&def, &context), "sph_context_create");
  return context;
}

// A small deterministic generator (support_random, xorshift64*), so every run builds the same
// scene.
struct Random {
  uint64_t state;
  explicit Random(uint64_t seed) : state(seed * 0x9E3779B97F4A7C15ull + 1) {}
  double uniform() { return support_random(&state); }  // [0, 1)
};

// FCC lattice points in a sphere (support_fcc_sphere: the lattice of sph_world_fill_sphere).
inline std::vector<float> fcc_sphere(float cx, float cy, float cz, float radius, float spacing) {
  const double centre[3] = {cx, cy, cz};
  float* points = nullptr;
  uint32_t n = 0;
  require_ok(support_fcc_sphere(centre, radius, spacing, &points, &n), "support_fcc_sphere");
  std::vector<float> p(points, points + 3 * static_cast<size_t>(n));
  std::free(points);
  return p;
}

struct SceneSpec {
  const char* name = "scene";
  sph_integrator integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
  float radius = 0.3f;  // sphere of particles at the origin
  float spacing = 0.02f;
  float random_speed = 0.0f;         // each velocity component uniform in [-s, s]
  sph_vec3 drift{0.0f, 0.0f, 0.0f};  // added to every velocity
  sph_vec3 gravity{0.0f, 0.0f, 0.0f};
  float step_factor = 0.4f;
  float dt_max = 1e-3f;
  uint32_t spare_capacity = 0;
  // Physics options (src/physics; CPU and CUDA must agree with them on too).
  sph_feature_flags features = SPH_FEATURE_NONE;
  sph_viscosity_method viscosity_method = SPH_VISCOSITY_MUELLER;
  sph_equation_of_state equation_of_state = SPH_EOS_IDEAL_GAS;
  uint32_t step_limits = 0;
  sph_solver solver = SPH_SOLVER_WCSPH;  // SPH_SOLVER_DFSPH: symplectic Euler, ideal gas (unused)
  // SPH_FEATURE_SPRINGS: stiff, damped and plastic, so linking, the force, the rest-length flow
  // and the dropping of springs all run.
  float spring_stiffness = 1e5f;
  float spring_damping = 50.0f;
  float spring_plasticity = 20.0f;
  float spring_yield_ratio = 0.02f;
};

struct Loaded {
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  uint32_t count = 0;
  void destroy() {
    sph_world_destroy(world);
    sph_context_destroy(context);
    world = nullptr;
    context = nullptr;
  }
};

inline Loaded load_scene(sph_backend backend, const SceneSpec& s) {
  Loaded l;
  l.context = make_context(backend);
  const std::vector<float> pos = fcc_sphere(0.0f, 0.0f, 0.0f, s.radius, s.spacing);
  l.count = static_cast<uint32_t>(pos.size() / 3);
  std::vector<float> vel(pos.size() + 3);
  Random random(12345);
  const float drift[3] = {s.drift.x, s.drift.y, s.drift.z};
  support_random_velocities(vel.data(), l.count, s.random_speed, drift, &random.state);
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = l.count + s.spare_capacity;
  def.particle_spacing = s.spacing;
  def.integrator = s.integrator;
  def.features = s.features;
  def.viscosity_method = s.viscosity_method;
  def.equation_of_state = s.equation_of_state;
  def.solver = s.solver;
  require_ok(sph_world_create(l.context, &def, &l.world), "sph_world_create");
  sph_world_params params;
  sph_world_params_init(&params);
  params.gravity = s.gravity;
  params.step_factor = s.step_factor;
  params.dt_max = s.dt_max;
  params.step_limits = s.step_limits;
  require_ok(sph_world_set_params(l.world, &params), "sph_world_set_params");
  if (s.features & SPH_FEATURE_SPRINGS) {
    sph_spring_params springs;
    sph_spring_params_init(&springs);
    springs.stiffness = s.spring_stiffness;
    springs.damping = s.spring_damping;
    springs.plasticity = s.spring_plasticity;
    springs.yield_ratio = s.spring_yield_ratio;
    require_ok(sph_world_set_spring_params(l.world, &springs), "sph_world_set_spring_params");
  }
  require_ok(support_spawn(l.world, pos.data(), vel.data(), l.count), "sph_world_spawn");
  return l;
}

// Every attribute of a world, indexed by particle id.
struct State {
  std::vector<float> position, velocity, density, pressure;
  std::vector<uint32_t> id;
  uint32_t count = 0;
};

// Every attribute of a world, in storage order (by_id false) or indexed by particle id
// (support_read_by_id: the ids must be 0..n-1, as in load_scene's scenes without sinks).
inline State read_attributes(const sph_world* world, bool by_id) {
  State out;
  uint32_t n = 0;
  require_ok(sph_world_get_particle_count(world, &n), "sph_world_get_particle_count");
  out.count = n;
  out.position.resize(3 * static_cast<size_t>(n));
  out.velocity.resize(3 * static_cast<size_t>(n));
  out.density.resize(n);
  out.pressure.resize(n);
  out.id.resize(n);
  auto read = by_id ? support_read_by_id : support_read;
  uint32_t count = 0;
  require_ok(read(world, SPH_ATTRIBUTE_POSITION, out.position.data(), n, &count), "copy positions");
  require_ok(read(world, SPH_ATTRIBUTE_VELOCITY, out.velocity.data(), n, &count), "copy velocities");
  require_ok(read(world, SPH_ATTRIBUTE_DENSITY, out.density.data(), n, &count), "copy densities");
  require_ok(read(world, SPH_ATTRIBUTE_PRESSURE, out.pressure.data(), n, &count), "copy pressures");
  require_ok(read(world, SPH_ATTRIBUTE_ID, out.id.data(), n, &count), "copy ids");
  return out;
}

inline State read_state(const sph_world* world) { return read_attributes(world, true); }

template <class T>
bool bitwise_equal(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

inline bool states_identical(const State& a, const State& b) {
  return a.count == b.count && bitwise_equal(a.position, b.position) &&
         bitwise_equal(a.velocity, b.velocity) && bitwise_equal(a.density, b.density) &&
         bitwise_equal(a.pressure, b.pressure) && bitwise_equal(a.id, b.id);
}

// The largest length of the 3-vectors packed in v (x, y, z, x, ...).
inline double max_abs(const std::vector<float>& v) {
  double m = 0.0;
  for (size_t i = 0; i < v.size(); i += 3)
    m = std::max(m,
                 std::sqrt(double(v[i]) * v[i] + double(v[i + 1]) * v[i + 1] + double(v[i + 2]) * v[i + 2]));
  return m;
}

// The largest distance between the packed 3-vectors of a and b, element by element.
inline double max_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0.0;
  for (size_t i = 0; i < a.size(); i += 3) {
    const double dx = double(a[i]) - b[i], dy = double(a[i + 1]) - b[i + 1], dz = double(a[i + 2]) - b[i + 2];
    m = std::max(m, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  return m;
}

inline sph_stats get_stats(const sph_world* world) {
  sph_stats s;
  sph_stats_init(&s);
  require_ok(sph_world_get_stats(world, &s), "sph_world_get_stats");
  return s;
}

// The dam break of check_loads and check_caller_state: a 0.6 x 0.4 x 0.2 m tank
// (support_tank_between) with a fixed 8 cm box standing in it at x = 0.4 and a 0.2 x 0.3 x 0.2 m
// column of water at its left end, both SDFs of `voxel`-sized voxels. The caller destroys the
// SDFs after the world.
struct TankWithBox {
  sph_sdf* tank = nullptr;
  sph_sdf* box = nullptr;
  sph_collider_id tank_collider{}, box_collider{};
};

inline TankWithBox add_tank_with_box(sph_context* context, sph_world* world, double voxel) {
  TankWithBox t;
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {0.6, 0.4, 0.2};
  require_ok(support_tank_between(context, world, lo, hi, voxel, 0.0f, &t.tank, &t.tank_collider), "tank");
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents = sph_vec3{0.04f, 0.04f, 0.04f};
  shape.voxel_size = static_cast<float>(voxel);
  shape.padding_voxels = 8;
  require_ok(sph_sdf_create_shape(context, &shape, &t.box), "box");
  sph_collider_def c;
  sph_collider_def_init(&c);
  c.sdf = t.box;
  c.transform = sph_transform_identity();
  c.transform.position = sph_vec3{0.4f, 0.04f, 0.1f};
  require_ok(sph_collider_create(world, &c, &t.box_collider), "box collider");
  sph_fill_box_desc column;
  sph_fill_box_desc_init(&column);
  column.max = sph_vec3{0.2f, 0.3f, 0.2f};
  require_ok(sph_world_fill_box(world, &column, nullptr), "fill");
  return t;
}

}  // namespace gpu_check
