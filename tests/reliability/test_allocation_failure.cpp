// SPDX-License-Identifier: MIT
// Host allocation failures (issue 9, item 6), injected at every allocation point of every
// call in turn.
//
// This executable replaces the global operator new (tests/support/allocation_injector.h; libsph
// resolves it from the executable, since the library exports nothing but sph_*). Armed with n, the n-th
// allocation from then on throws std::bad_alloc (or returns null for the nothrow forms), once, on
// whichever thread makes it. For each call below, n runs 0, 1, 2, ... until the call completes
// without reaching the n-th allocation. A call marked fresh_scene runs each n on a scene built
// afresh, so every allocation it makes fails once; the others run each n on the scene the last
// failure left, which is cheaper but can skip a few points (a failed run may keep storage it grew:
// Call::fresh_scene); SPH_TEST_FRESH_SCENES=1 runs every call on fresh scenes (about 30 s in
// Release). Each failure must come back as SPH_ERROR_OUT_OF_HOST_MEMORY with a message,
// leave the world bitwise as it was (its particles, its checkpoint's bytes, its probe readings,
// loads, events and step statistics), the live object count and the open file descriptors
// unchanged, and the world must then go on exactly as an undisturbed copy. The calls run against
// small scenes (a tank of a few hundred particles) on worlds of several methods and features, and
// a few steps against a large tank on the engine's task system, whose loops run in blocks on the
// pool's threads.
//
// It runs through the C API on the backend SPH_TEST_BACKEND names, so scripts/gpu-test runs it
// on the CUDA backend too (host allocations of the CUDA backend: staging, scene uploads, ...).
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <new>
#include <string>
#include <vector>

extern "C" {
#include "capi_async.h"
#include "capi_test.h"
#include "task_pool.h"
}
#include "allocation_injector.h"

using alloc_fault::arm;
using alloc_fault::disarm;

// ---- the scene every call runs against ----------------------------------------------------------
namespace {

constexpr uint32_t kCapacity = CAPI_SNAPSHOT_MAX;
constexpr float kFrameDt = 1.0f / 60.0f;
// The large tank (build_large_scene_on_tasks): more particles than the CPU backend's loops need
// to split into blocks (src/cpu/cpu_parallel.h: kParallelMinimum, 4,096 particles, in blocks of
// kParticleChunk, 1,024), so that its loops go to the engine's task system as tasks of several
// items, which the pool's threads run. Its calls step short frames (two substeps, not the small
// tank's 17): a step's allocation points repeat with every substep, and the large tank's steps
// are what this test's time goes to.
constexpr uint32_t kLargeCapacity = 6144;
constexpr uint32_t kLargeMinimum = 4096 + 1024;  // after the sink's removals: five blocks at least
constexpr float kShortFrameDt = 2e-3f;

struct Scene {
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  sph_sdf* tank = nullptr;  // kept, so calls can create more colliders, sources and sinks
  sph_sdf* blob = nullptr;
  sph_collider_id tank_collider{};
  // What the state checks read besides the particles (empty ids: none).
  sph_probe_id probes[3]{};
  bool loads = false;  // the world has SPH_FEATURE_COLLIDER_LOADS: read the tank's loads
  sph_collider_id blob_collider{};
  std::vector<unsigned char> checkpoint;  // a checkpoint of the scene a frame ago (restore, load)
  float frame_dt = kFrameDt;              // the frame its calls step (and the checks after them)
};

sph_transform at(float x, float y, float z) {
  sph_transform t = sph_transform_identity();
  t.position.x = x;
  t.position.y = y;
  t.position.z = z;
  return t;
}

// A tank with a sloshing block of water, a continuous source, a sink and a force field, on a world
// of `features` and `solver`, no frame behind it yet (build_scene adds one).
// Set while a scene is built on the engine's task system (build_scene_on_tasks), and while the
// large tank is built (build_large_scene_on_tasks).
bool g_on_task_pool = false;
bool g_large = false;

void build_world(Scene* s, sph_feature_flags features, sph_solver solver) {
  sph_context_def cdef;
  EXPECT_OK(sph_test_context_def_init(&cdef));
  cdef.cpu_worker_count = 1;
  if (g_on_task_pool) {
    // The engine's task system is the CPU backend's (sph_context_def.enqueue_task): a CPU context
    // whatever SPH_TEST_BACKEND says, its loops and an asynchronous step as tasks of the test's pool.
    // With a task system cpu_worker_count only says whether loops run in parallel: 1 would keep
    // every loop on the calling thread whatever the particle count.
    cdef.backend = SPH_BACKEND_CPU;
    cdef.cpu_worker_count = kTaskPoolThreads + 1;
    task_pool_use(&cdef);
  }
  EXPECT_OK(sph_context_create(&cdef, &s->context));
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = g_large ? kLargeCapacity : kCapacity;
  def.particle_spacing = 0.025f;
  def.features = features;
  def.solver = solver;
  EXPECT_OK(sph_world_create(s->context, &def, &s->world));
  sph_world_params params;
  sph_world_params_init(&params);
  params.gravity.x = 2.0f;
  params.max_substeps = 100;
  EXPECT_OK(sph_world_set_params(s->world, &params));

  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents = g_large ? sph_vec3{0.3f, 0.3f, 0.2f} : sph_vec3{0.2f, 0.2f, 0.1f};
  shape.voxel_size = 0.025f;
  EXPECT_OK(sph_sdf_create_shape(s->context, &shape, &s->tank));
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.04f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(s->context, &shape, &s->blob));

  sph_collider_def collider;
  sph_collider_def_init(&collider);
  collider.sdf = s->tank;
  collider.flags = SPH_COLLIDER_FLAG_INVERTED;
  EXPECT_OK(sph_collider_create(s->world, &collider, &s->tank_collider));

  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = g_large ? sph_vec3{-0.28f, -0.28f, -0.18f} : sph_vec3{-0.18f, -0.18f, -0.08f};
  box.max = g_large ? sph_vec3{0.28f, 0.06f, 0.18f} : sph_vec3{-0.05f, 0.0f, 0.08f};
  uint32_t filled = 0;
  EXPECT_OK(sph_world_fill_box(s->world, &box, &filled));
  if (g_large)
    assert_true(filled >= kLargeMinimum + 100u && filled < kLargeCapacity - 150u);
  else
    assert_true(filled > 100u && filled < kCapacity - 150u);

  sph_source_def source;
  sph_source_def_init(&source);
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.region = s->blob;
  source.transform = at(0.1f, 0.1f, 0.0f);
  source.rate = 600.0f;
  sph_source_id source_id;
  EXPECT_OK(sph_source_create(s->world, &source, &source_id));

  sph_sink_def sink;
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_REGION;
  sink.region = s->blob;
  sink.transform = at(0.15f, -0.17f, 0.0f);
  sph_sink_id sink_id;
  EXPECT_OK(sph_sink_create(s->world, &sink, &sink_id));

  sph_force_field_def field;
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  field.vector = sph_vec3{0.0f, 0.0f, 1.0f};
  field.strength = 1.0f;
  sph_force_field_id field_id;
  EXPECT_OK(sph_force_field_create(s->world, &field, &field_id));
}

// The tank, one frame behind it: every part of a frame has state to roll back.
void build_scene(Scene* s) {
  build_world(s, SPH_FEATURE_NONE, SPH_SOLVER_WCSPH);
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

// The tank on a CPU context that runs its work on the engine's task system (tests/capi/task_pool.h,
// three threads of the test's own): a failure on a pool thread, inside the asynchronous step's
// task, must come back from the wait as it does from the world's own thread.
void build_scene_on_tasks(Scene* s) {
  g_on_task_pool = true;
  build_scene(s);
  g_on_task_pool = false;
}

// The large tank, one short frame behind it, on the engine's task system (its loops in blocks on
// the pool's threads).
void build_large_world_on_tasks(Scene* s, sph_solver solver) {
  g_on_task_pool = g_large = true;
  build_world(s, SPH_FEATURE_NONE, solver);
  g_on_task_pool = g_large = false;
  s->frame_dt = kShortFrameDt;
  EXPECT_OK(sph_world_step(s->world, s->frame_dt));
  uint32_t count = 0;
  EXPECT_OK(sph_world_get_particle_count(s->world, &count));
  assert_true(count >= kLargeMinimum);
}
void build_large_scene_on_tasks(Scene* s) { build_large_world_on_tasks(s, SPH_SOLVER_WCSPH); }
void build_large_dfsph_scene_on_tasks(Scene* s) { build_large_world_on_tasks(s, SPH_SOLVER_DFSPH); }

void destroy_scene(Scene* s) {
  EXPECT_OK(sph_world_destroy(s->world));
  EXPECT_OK(sph_sdf_destroy(s->tank));
  EXPECT_OK(sph_sdf_destroy(s->blob));
  EXPECT_OK(sph_context_destroy(s->context));
  *s = Scene{};
}

uint32_t live_objects() {
  uint32_t n = 0;
  EXPECT_OK(sph_get_live_object_count(&n));
  return n;
}

// ---- the other scenes: the tank on worlds of other methods, with probes, loads, ... --------------
// Each is the tank above with what its calls need; those named "new_*" add an object after the
// frame, so that the next step is its first (probe buffers grown, boundary-density maps made).

// The frames the probe and loads scenes run before their calls: the block falls the 2 cm onto the
// tank's floor, so that the walls take loads and the probes read pressure.
constexpr int kSettleFrames = 6;
void settle(Scene* s) {
  for (int i = 0; i < kSettleFrames; ++i) EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

sph_probe_id add_probe(sph_world* world, sph_probe_kind kind, sph_probe_sampling sampling, float x) {
  sph_probe_def def;
  sph_probe_def_init(&def);
  def.kind = kind;
  def.sampling = sampling;
  def.position = sph_vec3{x, -0.19f, 0.0f};
  def.length = 0.3f;
  sph_probe_id id;
  EXPECT_OK(sph_probe_create(world, &def, &id));
  return id;
}

// A point probe sampled every frame and a gauge sampled every substep, with readings.
void build_probe_scene(Scene* s) {
  build_world(s, SPH_FEATURE_NONE, SPH_SOLVER_WCSPH);
  s->probes[0] = add_probe(s->world, SPH_PROBE_POINT, SPH_PROBE_EVERY_FRAME, -0.1f);
  s->probes[1] = add_probe(s->world, SPH_PROBE_GAUGE, SPH_PROBE_EVERY_SUBSTEP, -0.12f);
  EXPECT_OK(sph_probe_set_pressure_threshold(s->world, s->probes[0], 1.0f));
  settle(s);
}
void build_new_probe_scene(Scene* s) {
  build_probe_scene(s);
  s->probes[2] = add_probe(s->world, SPH_PROBE_GAUGE, SPH_PROBE_EVERY_FRAME, -0.08f);
}

sph_collider_id add_blob_collider(Scene* s) {
  sph_collider_def def;
  sph_collider_def_init(&def);
  def.sdf = s->blob;
  def.transform = at(-0.1f, -0.15f, 0.0f);
  sph_collider_id id;
  EXPECT_OK(sph_collider_create(s->world, &def, &id));
  return id;
}

// Loads on the tank (and on a collider in the water for the "new" scene).
void build_loads_scene(Scene* s) {
  build_world(s, SPH_FEATURE_COLLIDER_LOADS, SPH_SOLVER_WCSPH);
  s->loads = true;
  settle(s);
}
void build_new_collider_loads_scene(Scene* s) {
  build_loads_scene(s);
  s->blob_collider = add_blob_collider(s);
}

void build_dfsph_scene(Scene* s) {
  build_world(s, SPH_FEATURE_NONE, SPH_SOLVER_DFSPH);
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}
// DFSPH with the walls in the density and their loads; the new collider's first step makes its
// asset's density map.
void build_dfsph_walls_scene(Scene* s) {
  build_world(s, SPH_FEATURE_BOUNDARY_DENSITY | SPH_FEATURE_COLLIDER_LOADS, SPH_SOLVER_DFSPH);
  s->loads = true;
  settle(s);
}
void build_new_collider_dfsph_walls_scene(Scene* s) {
  build_dfsph_walls_scene(s);
  s->blob_collider = add_blob_collider(s);
}

// Springs: the fill linked in the first frame, the source's particles link in each later one.
void build_springs_scene(Scene* s) {
  build_world(s, SPH_FEATURE_SPRINGS, SPH_SOLVER_WCSPH);
  sph_spring_params springs;
  sph_spring_params_init(&springs);
  springs.plasticity = 5.0f;
  springs.damping = 1.0f;
  EXPECT_OK(sph_world_set_spring_params(s->world, &springs));
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

void build_diffusion_scene(Scene* s) {
  build_world(s, SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION, SPH_SOLVER_WCSPH);
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

void build_user_attribute_scene(Scene* s) {
  build_world(s, SPH_FEATURE_USER_ATTRIBUTE, SPH_SOLVER_WCSPH);
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

// The tank with a checkpoint of itself taken before its frame (sph_world_restore goes back to it,
// sph_world_load makes a world of it).
void build_checkpoint_scene(Scene* s) {
  build_world(s, SPH_FEATURE_NONE, SPH_SOLVER_WCSPH);
  uint64_t size = 0;
  EXPECT_OK(sph_world_save(s->world, nullptr, 0, &size));
  s->checkpoint.resize(static_cast<size_t>(size));
  EXPECT_OK(sph_world_save(s->world, s->checkpoint.data(), size, &size));
  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

// ---- what a call must leave as it was -----------------------------------------------------------
// Besides the particles (capi_snapshot): the world's checkpoint (its scene, every method's state
// and parameters, the object tables and their id generations, the last step's report, events and
// removed ids), and what the scene's calls read that a checkpoint leaves out (probe readings,
// loads).
void append(std::vector<unsigned char>* out, const void* bytes, size_t size) {
  const unsigned char* b = static_cast<const unsigned char*>(bytes);
  out->insert(out->end(), b, b + size);
}

void checkpoint_of(const Scene* s, std::vector<unsigned char>* out) {
  // Into the storage the vector has from the last checkpoint, so that one save does (a size query
  // writes the whole checkpoint too, and the large tank's take milliseconds); a second when it
  // does not fit.
  out->resize(out->capacity() > 0 ? out->capacity() : 4096);
  uint64_t size = 0;
  sph_result r = sph_world_save(s->world, out->data(), out->size(), &size);
  if (r == SPH_ERROR_BUFFER_TOO_SMALL) {
    out->resize(static_cast<size_t>(size));
    r = sph_world_save(s->world, out->data(), out->size(), &size);
  }
  EXPECT_OK(r);
  out->resize(static_cast<size_t>(size));
}

// The particles as copy_attribute gives them (every one: capi_snapshot holds CAPI_SNAPSHOT_MAX,
// fewer than the large tank's), their count and the simulated time, as bytes.
void particles_of(const sph_world* world, std::vector<unsigned char>* out) {
  static std::vector<unsigned char> column;
  out->clear();
  uint32_t count = 0;
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  append(out, &count, sizeof count);
  sph_stats stats;
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  append(out, &stats.simulated_time, sizeof stats.simulated_time);
  const struct {
    sph_attribute attribute;
    size_t size;
  } columns[] = {{SPH_ATTRIBUTE_POSITION, 12},
                 {SPH_ATTRIBUTE_VELOCITY, 12},
                 {SPH_ATTRIBUTE_DENSITY, 4},
                 {SPH_ATTRIBUTE_ID, 4}};
  for (const auto& c : columns) {
    column.assign(c.size * count + 1, 0);  // (+1: an empty world's buffer is not empty)
    EXPECT_OK(
        sph_world_copy_attribute(world, c.attribute, column.data(), column.size(), 0, 0, count, nullptr));
    append(out, column.data(), c.size * count);
  }
}

// The readings, loads, events and removed ids, and the deterministic statistics of the last step
// (not its wall times or memory), as bytes.
void readouts_of(const Scene* s, std::vector<unsigned char>* out) {
  out->clear();
  for (const sph_probe_id& probe : s->probes) {
    if (probe.bits == 0) continue;
    sph_probe_reading reading;
    sph_probe_reading_init(&reading);
    EXPECT_OK(sph_probe_get_reading(s->world, probe, &reading));
    append(out, &reading, sizeof reading);
  }
  if (s->loads)
    for (const sph_collider_id& collider : {s->tank_collider, s->blob_collider}) {
      if (collider.bits == 0) continue;
      sph_collider_loads loads;
      sph_collider_loads_init(&loads);
      EXPECT_OK(sph_collider_get_loads(s->world, collider, &loads));
      append(out, &loads, sizeof loads);
    }
  sph_event events[16];
  uint32_t count = 0;
  EXPECT_OK(sph_world_get_events(s->world, events, 16, &count));
  append(out, &count, sizeof count);
  append(out, events, sizeof(sph_event) * (count < 16 ? count : 16));
  static uint32_t removed[kLargeCapacity];
  EXPECT_OK(sph_world_get_removed_ids(s->world, removed, kLargeCapacity, &count));
  append(out, &count, sizeof count);
  append(out, removed, sizeof(uint32_t) * count);
  sph_stats stats;
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(s->world, &stats));
  const float floats[] = {stats.frame_time,
                          stats.dt_min,
                          stats.dt_max,
                          stats.max_speed,
                          stats.density_min,
                          stats.density_mean,
                          stats.density_max,
                          stats.neighbors_mean,
                          stats.density_error_mean,
                          stats.density_error_max,
                          stats.divergence_error_mean,
                          stats.divergence_error_max};
  const uint32_t words[] = {stats.particle_count,
                            stats.substeps,
                            stats.neighbors_max,
                            stats.pressure_iterations,
                            stats.divergence_iterations,
                            stats.pressure_solves_capped,
                            stats.divergence_solves_capped,
                            stats.capacity};
  append(out, floats, sizeof floats);
  append(out, words, sizeof words);
}

void expect_same_bytes(const char* call, long n, const char* what, const std::vector<unsigned char>& before,
                       const std::vector<unsigned char>& now) {
  if (before == now) return;
  size_t at = 0;
  while (at < before.size() && at < now.size() && before[at] == now[at]) ++at;
  fail_msg("%s with allocation %ld failing: the %s changed (%zu -> %zu bytes, first difference at byte %zu)",
           call, n, what, before.size(), now.size(), at);
}

// ---- the calls ----------------------------------------------------------------------------------
// Each runs one call against the scene; objects it creates on success are released by `undo`
// (which runs unarmed).
// What the engine's task system (the tests' pool) must have run during a call's runs, counted
// over them all; a scene too small, or a context that keeps its loops on the calling thread,
// fails the call rather than silently covering less.
enum class OnPool {
  kUnchecked,
  // Loops in blocks: tasks of several items enqueued from the calling thread, items of them run
  // by the pool's threads.
  kLoops,
  // The asynchronous step as a task on a pool thread: allocations failing there, its loops tasks
  // enqueued from inside it (nested), items of those run by the pool's threads.
  kStepAndNestedLoops,
};

struct Call {
  const char* name;
  sph_result (*run)(Scene*);
  void (*undo)(Scene*);
  bool changes_world;  // on success: the scene is rebuilt for the next call
  void (*build)(Scene*);
  OnPool on_pool = OnPool::kUnchecked;
  void (*after_fault)(Scene*) = nullptr;  // more checks after each failure (unarmed)
  // Each run on a scene built afresh (else each on the scene the last failure left). A failed run
  // may keep storage it grew (a vector's capacity survives the rollback: the world's state is as
  // before, not its heap); the next run, not making that allocation again, then has the point
  // after it at its index, and that point is never failed: in place, a step on build_scene's tank
  // failed 83 of the 98 allocations it makes.
  bool fresh_scene = false;
  // The call may make no allocation (allocation_free below); any other call that reaches no
  // allocation point was not tested, and fails.
  bool may_allocate_nothing = false;
};

// A call that needs no allocation: a read or a parameter write (sph_c.h names no
// OUT_OF_HOST_MEMORY for it).
Call allocation_free(Call call) {
  call.may_allocate_nothing = true;
  return call;
}
// SPH_TEST_FRESH_SCENES=1: every call runs each n on a fresh scene, about 30 s in Release rather
// than 3 (main reads it).
bool g_fresh_scenes = false;

// The scene as it was before the call that is running (taken unarmed): the calls that name
// particles (remove, set_attribute) take them from here.
capi_snapshot g_before;
capi_snapshot g_reference;

sph_context* g_made_context = nullptr;
sph_world* g_made_world = nullptr;
sph_sdf* g_made_sdf = nullptr;

sph_result run_context_create(Scene*) {
  sph_context_def def;
  sph_test_context_def_init(&def);
  return sph_context_create(&def, &g_made_context);
}
void undo_context_create(Scene*) {
  EXPECT_OK(sph_context_destroy(g_made_context));
  g_made_context = nullptr;
}

sph_result run_world_create(Scene* s) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 1000;
  return sph_world_create(s->context, &def, &g_made_world);
}
void undo_world_create(Scene*) {
  EXPECT_OK(sph_world_destroy(g_made_world));
  g_made_world = nullptr;
}

sph_result run_sdf_create_shape(Scene* s) {
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_CUP;
  shape.radius = 0.05f;
  shape.half_height = 0.05f;
  shape.wall_thickness = 0.02f;
  shape.voxel_size = 0.02f;
  return sph_sdf_create_shape(s->context, &shape, &g_made_sdf);
}
void undo_sdf(Scene*) {
  EXPECT_OK(sph_sdf_destroy(g_made_sdf));
  g_made_sdf = nullptr;
}

sph_result run_fill_box(Scene* s) {
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{0.05f, -0.18f, -0.08f};
  box.max = sph_vec3{0.15f, -0.1f, 0.08f};
  return sph_world_fill_box(s->world, &box, nullptr);
}

sph_result run_fill_sphere(Scene* s) {
  sph_fill_sphere_desc sphere;
  sph_fill_sphere_desc_init(&sphere);
  sphere.center = sph_vec3{0.1f, 0.1f, 0.0f};
  sphere.radius = 0.05f;
  return sph_world_fill_sphere(s->world, &sphere, nullptr);
}

sph_result run_spawn(Scene* s) {
  float positions[3 * 8];
  for (int i = 0; i < 8; ++i) {
    positions[3 * i + 0] = 0.1f + 0.03f * static_cast<float>(i % 4);
    positions[3 * i + 1] = 0.15f;
    positions[3 * i + 2] = -0.03f + 0.06f * static_cast<float>(i / 4);
  }
  sph_spawn_desc desc;
  sph_spawn_desc_init(&desc);
  desc.positions = positions;
  desc.count = 8;
  return sph_world_spawn(s->world, &desc, nullptr);
}

sph_result run_set_params(Scene* s) {
  sph_world_params params;
  sph_world_params_init(&params);
  sph_world_get_params(s->world, &params);
  params.viscosity = 2.0f;
  return sph_world_set_params(s->world, &params);
}

sph_result run_collider_create(Scene* s) {
  sph_collider_def def;
  sph_collider_def_init(&def);
  def.sdf = s->blob;
  def.transform = at(0.0f, -0.1f, 0.0f);
  sph_collider_id id;
  return sph_collider_create(s->world, &def, &id);
}

sph_result run_source_create(Scene* s) {
  sph_source_def def;
  sph_source_def_init(&def);
  def.region = s->blob;
  def.transform = at(-0.1f, 0.12f, 0.0f);
  sph_source_id id;
  return sph_source_create(s->world, &def, &id);
}

sph_result run_sink_create(Scene* s) {
  sph_sink_def def;
  sph_sink_def_init(&def);
  def.mode = SPH_SINK_OUTSIDE_BOUNDS;
  def.bounds_min = sph_vec3{-1.0f, -1.0f, -1.0f};
  def.bounds_max = sph_vec3{1.0f, 1.0f, 1.0f};
  sph_sink_id id;
  return sph_sink_create(s->world, &def, &id);
}

sph_result run_force_field_create(Scene* s) {
  sph_force_field_def def;
  sph_force_field_def_init(&def);
  def.kind = SPH_FORCE_FIELD_RADIAL;
  def.region = s->blob;
  def.strength = -2.0f;
  sph_force_field_id id;
  return sph_force_field_create(s->world, &def, &id);
}

sph_result run_step(Scene* s) { return sph_world_step(s->world, s->frame_dt); }

sph_result run_copy_and_stats(Scene* s) {
  static float positions[3 * kCapacity];
  sph_result r = sph_world_copy_attribute(s->world, SPH_ATTRIBUTE_POSITION, positions, sizeof positions, 0, 0,
                                          kCapacity, nullptr);
  if (r != SPH_OK) return r;
  sph_stats stats;
  sph_stats_init(&stats);
  r = sph_world_get_stats(s->world, &stats);
  if (r != SPH_OK) return r;
  sph_event events[8];
  uint32_t count = 0;
  return sph_world_get_events(s->world, events, 8, &count);
}

sph_result run_probe_create(Scene* s) {
  sph_probe_def def;
  sph_probe_def_init(&def);
  def.kind = SPH_PROBE_GAUGE;
  def.sampling = SPH_PROBE_EVERY_SUBSTEP;
  def.position = sph_vec3{0.0f, -0.19f, 0.0f};
  def.length = 0.3f;
  sph_probe_id id;
  return sph_probe_create(s->world, &def, &id);
}

sph_result run_probe_set_pressure_threshold(Scene* s) {
  return sph_probe_set_pressure_threshold(s->world, s->probes[1], 2.0f);
}

sph_result run_probe_get_reading(Scene* s) {
  sph_probe_reading reading;
  sph_probe_reading_init(&reading);
  sph_result r = sph_probe_get_reading(s->world, s->probes[0], &reading);
  if (r != SPH_OK) return r;
  return sph_probe_get_reading(s->world, s->probes[1], &reading);
}

sph_result run_collider_set_load_point(Scene* s) {
  const sph_vec3 point = {0.0f, -0.2f, 0.0f};
  return sph_collider_set_load_point(s->world, s->tank_collider, &point);
}

sph_result run_collider_get_loads(Scene* s) {
  sph_collider_loads loads;
  sph_collider_loads_init(&loads);
  return sph_collider_get_loads(s->world, s->tank_collider, &loads);
}

sph_result run_set_spring_params(Scene* s) {
  sph_spring_params params;
  sph_spring_params_init(&params);
  EXPECT_OK(sph_world_get_spring_params(s->world, &params));
  params.stiffness = 2e4f;
  params.yield_ratio = 0.2f;
  return sph_world_set_spring_params(s->world, &params);
}

sph_result run_set_density_diffusion_params(Scene* s) {
  sph_density_diffusion_params params;
  sph_density_diffusion_params_init(&params);
  params.delta = 0.2f;
  return sph_world_set_density_diffusion_params(s->world, &params);
}

// The first 8 particles' positions moved by a millimetre, their velocities and user values.
sph_result run_set_positions(Scene* s) {
  float positions[3 * 8];
  for (int i = 0; i < 3 * 8; ++i) positions[i] = g_before.positions[i] + 0.001f;
  return sph_world_set_attribute(s->world, SPH_ATTRIBUTE_POSITION, positions, sizeof positions, 0, 0, 8);
}

sph_result run_set_velocities(Scene* s) {
  float velocities[3 * 8];
  for (int i = 0; i < 3 * 8; ++i) velocities[i] = 0.1f * static_cast<float>(i % 3);
  return sph_world_set_attribute(s->world, SPH_ATTRIBUTE_VELOCITY, velocities, sizeof velocities, 0, 0, 8);
}

sph_result run_set_user_attributes(Scene* s) {
  uint32_t values[8];
  for (uint32_t i = 0; i < 8; ++i) values[i] = 7u * i + 1u;
  return sph_world_set_attribute(s->world, SPH_ATTRIBUTE_USER, values, sizeof values, 0, 3, 8);
}

// The first, a middle and the last particle of the world's order, by id.
sph_result run_remove_particles(Scene* s) {
  const uint32_t ids[3] = {g_before.ids[0], g_before.ids[g_before.count / 2],
                           g_before.ids[g_before.count - 1]};
  return sph_world_remove_particles(s->world, ids, 3);
}

// The size query, then the checkpoint itself.
sph_result run_save(Scene* s) {
  static unsigned char buffer[1u << 22];
  uint64_t size = 0;
  sph_result r = sph_world_save(s->world, nullptr, 0, &size);
  if (r != SPH_OK) return r;
  assert_true(size <= sizeof buffer);
  return sph_world_save(s->world, buffer, sizeof buffer, &size);
}

sph_result run_restore(Scene* s) {
  return sph_world_restore(s->world, s->checkpoint.data(), s->checkpoint.size());
}

sph_result run_load(Scene* s) {
  return sph_world_load(s->context, s->checkpoint.data(), s->checkpoint.size(), &g_made_world);
}

// Checkpoint files, in a folder of this test's own (main makes it and removes it). The path is
// made before any run: the test's own allocations must not take the library's allocation points.
std::string g_checkpoint_folder;
std::string g_checkpoint_file;

std::vector<std::string> checkpoint_folder_entries() {
  std::vector<std::string> names;
  DIR* folder = opendir(g_checkpoint_folder.c_str());
  assert_non_null(folder);
  while (const dirent* entry = readdir(folder))
    if (strcmp(entry->d_name, ".") != 0 && strcmp(entry->d_name, "..") != 0) names.push_back(entry->d_name);
  closedir(folder);
  return names;
}

std::vector<unsigned char> file_bytes(const char* path) {
  std::vector<unsigned char> bytes;
  FILE* file = fopen(path, "rb");
  assert_non_null(file);
  unsigned char chunk[1 << 16];
  size_t n;
  while ((n = fread(chunk, 1, sizeof chunk, file)) > 0) bytes.insert(bytes.end(), chunk, chunk + n);
  assert_int_equal(ferror(file), 0);
  fclose(file);
  return bytes;
}

void write_file(const char* path, const std::vector<unsigned char>& bytes) {
  FILE* file = fopen(path, "wb");
  assert_non_null(file);
  assert_int_equal(fwrite(bytes.data(), 1, bytes.size(), file), bytes.size());
  assert_int_equal(fclose(file), 0);
}

sph_result run_save_file(Scene* s) { return sph_world_save_file(s->world, g_checkpoint_file.c_str()); }

// A failed save leaves the folder as it was: no temporary file, and at the path nothing, or the
// file that was there (the scene's checkpoint when it has one: build_checkpoint_file_scene).
void expect_no_file_saved(Scene* s) {
  const std::vector<std::string> names = checkpoint_folder_entries();
  const size_t expected = s->checkpoint.empty() ? 0 : 1;
  if (names.size() != expected)
    fail_msg("sph_world_save_file failed but left %zu entries in the folder (%zu before; '%s')", names.size(),
             expected, names.empty() ? "" : names.back().c_str());
  if (expected == 1)
    expect_same_bytes("sph_world_save_file", -1, "file it was to replace", s->checkpoint,
                      file_bytes(g_checkpoint_file.c_str()));
}

// The file holds the checkpoint sph_world_save gives, and nothing else is left beside it.
void check_saved_file(Scene* s) {
  std::vector<unsigned char> expected;
  checkpoint_of(s, &expected);
  expect_same_bytes("sph_world_save_file", -1, "file (against sph_world_save)", expected,
                    file_bytes(g_checkpoint_file.c_str()));
  const std::vector<std::string> names = checkpoint_folder_entries();
  assert_int_equal(names.size(), 1);
  assert_int_equal(unlink(g_checkpoint_file.c_str()), 0);
}

// The checkpoint scene with its checkpoint (taken before its frame) in a file.
void build_checkpoint_file_scene(Scene* s) {
  build_checkpoint_scene(s);
  write_file(g_checkpoint_file.c_str(), s->checkpoint);
}

sph_result run_load_file(Scene* s) {
  return sph_world_load_file(s->context, g_checkpoint_file.c_str(), &g_made_world);
}

// A failed load writes no world.
void expect_no_world_loaded(Scene*) {
  if (g_made_world != nullptr) fail_msg("%s", "sph_world_load_file failed but wrote *out");
}

// The world loaded from the file saves the file's bytes again; the file goes (the next scene
// writes it again).
void check_loaded_file(Scene* s) {
  Scene loaded;
  loaded.world = g_made_world;
  std::vector<unsigned char> bytes;
  checkpoint_of(&loaded, &bytes);
  expect_same_bytes("sph_world_load_file", -1, "loaded world's checkpoint (against the file)", s->checkpoint,
                    bytes);
  undo_world_create(s);
  assert_int_equal(unlink(g_checkpoint_file.c_str()), 0);
}

// The asynchronous step: the frame runs on the world's own thread (started by the first begin of
// a scene; the injector counts that thread's allocations too). A failure inside the frame comes
// back from the wait, the world rolled back as sph_world_step rolls it back.
sph_result run_step_async(Scene* s) {
  const sph_result r = sph_world_step_begin(s->world, s->frame_dt);
  if (r != SPH_OK) return r;
  return sph_world_step_wait(s->world);
}

// The same, the frame left to the pool's threads until it is done (sph_world_step_poll never runs
// it): the wait's finish_task would otherwise run the task on this thread if no pool thread had
// taken it yet. So the frame and its failures are on a pool thread, and its loops are tasks
// enqueued from inside a task.
sph_result run_step_async_on_pool(Scene* s) {
  const sph_result r = sph_world_step_begin(s->world, s->frame_dt);
  if (r != SPH_OK) return r;
  capi_poll_until_done(s->world);
  return sph_world_step_wait(s->world);
}

void no_undo(Scene*) {}

const Call kCalls[] = {
    {"sph_context_create", run_context_create, undo_context_create, false, build_scene},
    {"sph_world_create", run_world_create, undo_world_create, false, build_scene},
    {"sph_sdf_create_shape", run_sdf_create_shape, undo_sdf, false, build_scene},
    {"sph_world_fill_box", run_fill_box, no_undo, true, build_scene},
    {"sph_world_fill_sphere", run_fill_sphere, no_undo, true, build_scene},
    {"sph_world_spawn", run_spawn, no_undo, true, build_scene},
    allocation_free(Call{"sph_world_set_params", run_set_params, no_undo, true, build_scene}),
    {"sph_collider_create", run_collider_create, no_undo, true, build_scene},
    {"sph_source_create", run_source_create, no_undo, true, build_scene},
    {"sph_sink_create", run_sink_create, no_undo, true, build_scene},
    {"sph_force_field_create", run_force_field_create, no_undo, true, build_scene},
    {"sph_world_step", run_step, no_undo, true, build_scene, OnPool::kUnchecked, nullptr, true},
    allocation_free(
        Call{"copy_attribute + get_stats + get_events", run_copy_and_stats, no_undo, false, build_scene}),
    // The calls whose errors in sph_c.h name no OUT_OF_HOST_MEMORY (a probe's threshold and reading,
    // a collider's load point and loads, the springs' and the density diffusion's parameters)
    // allocate nothing: they run once, with no failure to inject (one that starts to allocate is
    // checked as every other call).
    // Probes and gauges.
    {"sph_probe_create", run_probe_create, no_undo, true, build_probe_scene},
    allocation_free(Call{"sph_probe_set_pressure_threshold", run_probe_set_pressure_threshold, no_undo, true,
                         build_probe_scene}),
    {"sph_world_step (a new probe)", run_step, no_undo, true, build_new_probe_scene},
    allocation_free(Call{"sph_probe_get_reading", run_probe_get_reading, no_undo, false, build_probe_scene}),
    // Loads on colliders.
    allocation_free(
        Call{"sph_collider_set_load_point", run_collider_set_load_point, no_undo, true, build_loads_scene}),
    {"sph_world_step (loads, a new collider)", run_step, no_undo, true, build_new_collider_loads_scene},
    allocation_free(
        Call{"sph_collider_get_loads", run_collider_get_loads, no_undo, false, build_loads_scene}),
    // DFSPH, also with the walls in the density (and their loads).
    {"sph_world_step (DFSPH)", run_step, no_undo, true, build_dfsph_scene},
    {"sph_world_step (DFSPH, walls, a new collider)", run_step, no_undo, true,
     build_new_collider_dfsph_walls_scene},
    // Springs, density diffusion.
    allocation_free(
        Call{"sph_world_set_spring_params", run_set_spring_params, no_undo, true, build_springs_scene}),
    {"sph_world_step (springs)", run_step, no_undo, true, build_springs_scene},
    {"sph_world_remove_particles (springs)", run_remove_particles, no_undo, true, build_springs_scene},
    allocation_free(Call{"sph_world_set_density_diffusion_params", run_set_density_diffusion_params, no_undo,
                         true, build_diffusion_scene}),
    {"sph_world_step (density diffusion)", run_step, no_undo, true, build_diffusion_scene},
    // Writing and removing particles.
    {"sph_world_set_attribute (position)", run_set_positions, no_undo, true, build_user_attribute_scene},
    {"sph_world_set_attribute (velocity)", run_set_velocities, no_undo, true, build_user_attribute_scene},
    {"sph_world_set_attribute (user)", run_set_user_attributes, no_undo, true, build_user_attribute_scene},
    {"sph_world_remove_particles", run_remove_particles, no_undo, true, build_scene},
    // Checkpoints in memory.
    {"sph_world_save", run_save, no_undo, false, build_scene},
    {"sph_world_restore", run_restore, no_undo, true, build_checkpoint_scene},
    {"sph_world_load", run_load, undo_world_create, false, build_checkpoint_scene},
    // Checkpoint files.
    {"sph_world_save_file", run_save_file, check_saved_file, false, build_scene, OnPool::kUnchecked,
     expect_no_file_saved},
    {"sph_world_save_file (replacing a file)", run_save_file, check_saved_file, false,
     build_checkpoint_file_scene, OnPool::kUnchecked, expect_no_file_saved},
    {"sph_world_load_file", run_load_file, check_loaded_file, false, build_checkpoint_file_scene,
     OnPool::kUnchecked, expect_no_world_loaded},
    // The asynchronous step (one allocation point more than sph_world_step's: the world's thread,
    // which the scene's first begin starts).
    {"sph_world_step_begin + sph_world_step_wait", run_step_async, no_undo, true, build_scene,
     OnPool::kUnchecked, nullptr, true},
    // The same on the engine's task system: the asynchronous step as a task of a pool (allocations
    // on its threads fail in turn too: the injector counts them all).
    {"sph_world_step (the engine's task system)", run_step, no_undo, true, build_scene_on_tasks},
    {"sph_world_step_begin + sph_world_step_wait (the engine's task system)", run_step_async, no_undo, true,
     build_scene_on_tasks},
    // The large tank on the engine's task system: its loops in blocks, tasks of the pool (failures
    // on the calling thread between them), and the asynchronous step as a task on a pool thread,
    // its loops tasks enqueued from inside it. The loops' blocks allocate nothing (CpuParallel:
    // they must not throw), so the synchronous steps' failures all come on the calling thread.
    // DFSPH's step runs in place: 46 of the 48 points a fresh scene's step makes (the other two are
    // second instances of sites it fails), where fresh scenes took 6 s more under the sanitizers.
    {"sph_world_step (the engine's task system, the large tank)", run_step, no_undo, true,
     build_large_scene_on_tasks, OnPool::kLoops, nullptr, true},
    {"sph_world_step_begin + sph_world_step_wait (the engine's task system, the large tank)",
     run_step_async_on_pool, no_undo, true, build_large_scene_on_tasks, OnPool::kStepAndNestedLoops, nullptr,
     true},
    {"sph_world_step (DFSPH, the engine's task system, the large tank)", run_step, no_undo, true,
     build_large_dfsph_scene_on_tasks, OnPool::kLoops},
};

// The process's open file descriptors (-1: /proc/self/fd cannot be read, and nothing is checked).
int open_descriptors() {
  DIR* fds = opendir("/proc/self/fd");
  if (!fds) return -1;
  int n = 0;
  while (readdir(fds)) ++n;
  closedir(fds);
  return n;
}

void check_call(const Call& call) {
  // (static: the vectors keep their storage from call to call)
  static std::vector<unsigned char> checkpoint_before, checkpoint_now, readouts_before, readouts_now,
      particles_before, particles_now;
  Scene scene;
  call.build(&scene);
  // What the pool ran during the runs (not during the builds and checks between them).
  uint32_t tasks = 0, items = 0, nested = 0, nested_items = 0;
  long faults = 0, faults_elsewhere = 0;
  bool fits = false;  // the world's particles fit a capi_snapshot
  uint32_t objects_before = 0;
  int descriptors_before = 0;
  for (long n = 0, taken = -1;; ++n) {
    // The state before the run; after a failure that left it as it was, what the checks read.
    if (taken != n) {
      uint32_t count = 0;
      EXPECT_OK(sph_world_get_particle_count(scene.world, &count));
      fits = count <= CAPI_SNAPSHOT_MAX;
      if (fits) capi_snapshot_take(scene.world, &g_before);
      particles_of(scene.world, &particles_before);
      checkpoint_of(&scene, &checkpoint_before);
      readouts_of(&scene, &readouts_before);
      objects_before = live_objects();
      descriptors_before = open_descriptors();
    }
    const uint32_t tasks_before = task_pool_tasks(), items_before = task_pool_items_on_pool(),
                   nested_before = task_pool_nested(), nested_items_before = task_pool_nested_items_on_pool();
    arm(n);
    const sph_result r = call.run(&scene);
    const bool injected = disarm();
    tasks += task_pool_tasks() - tasks_before;
    items += task_pool_items_on_pool() - items_before;
    nested += task_pool_nested() - nested_before;
    nested_items += task_pool_nested_items_on_pool() - nested_items_before;
    if (!injected) {
      // The call made fewer than n + 1 allocations: it ran to the end.
      if (r != SPH_OK)
        fail_msg("%s without a fault: %s (%s)", call.name, sph_result_string(r), sph_get_last_error());
      call.undo(&scene);
      break;
    }
    ++faults;
    if (alloc_fault::injected_on_another_thread()) ++faults_elsewhere;
    if (r == SPH_OK) {
      // The library absorbed the failure (a fallback that does not need the memory): the call
      // must still have done its whole job, which the next iterations cannot tell apart from a
      // clean run; start again from a fresh scene so the remaining allocation points are reached
      // from the same state.
      call.undo(&scene);
      destroy_scene(&scene);
      call.build(&scene);
      continue;
    }
    if (r != SPH_ERROR_OUT_OF_HOST_MEMORY)
      fail_msg("%s with allocation %ld failing returned %s (%s), not SPH_ERROR_OUT_OF_HOST_MEMORY", call.name,
               n, sph_result_string(r), sph_get_last_error());
    if (strstr(sph_get_last_error(), "alloc") == nullptr && strstr(sph_get_last_error(), "memory") == nullptr)
      fail_msg("%s: the message does not say what ran out: '%s'", call.name, sph_get_last_error());
    if (live_objects() != objects_before)
      fail_msg("%s with allocation %ld failing leaked a handle", call.name, n);
    if (open_descriptors() != descriptors_before)
      fail_msg("%s with allocation %ld failing left %d file descriptors open (%d before)", call.name, n,
               open_descriptors(), descriptors_before);
    if (fits) EXPECT_UNCHANGED(scene.world, &g_before);
    particles_of(scene.world, &particles_now);
    expect_same_bytes(call.name, n, "particles", particles_before, particles_now);
    checkpoint_of(&scene, &checkpoint_now);
    expect_same_bytes(call.name, n, "checkpoint", checkpoint_before, checkpoint_now);
    readouts_of(&scene, &readouts_now);
    expect_same_bytes(call.name, n, "readings, loads, events or statistics", readouts_before, readouts_now);
    if (call.after_fault) call.after_fault(&scene);
    if (call.fresh_scene || g_fresh_scenes) {
      destroy_scene(&scene);
      call.build(&scene);
    } else {
      taken = n + 1;  // (the state before the next run is the one just checked)
    }
  }
  // On the CPU backend the counts are known (docs/reliability.md); another backend may do a call's
  // work without a host allocation (a device copy), so there a call without points is reported.
  if (faults == 0 && !call.may_allocate_nothing) {
    sph_backend backend = SPH_BACKEND_AUTO;
    EXPECT_OK(sph_context_get_backend(scene.context, &backend));
    if (backend == SPH_BACKEND_CPU)
      fail_msg("%s: no allocation point was reached (0 failed), so nothing was tested", call.name);
    print_message("%s: no host allocation point on this backend\n", call.name);
  }
  if (call.on_pool == OnPool::kUnchecked) {
    print_message("%-45s %ld allocation points failed once each\n", call.name, faults);
  } else {
    print_message(
        "%-45s %ld allocation points failed once each, %ld of them on other threads; %u tasks on the "
        "pool (%u nested), the pool's threads ran %u items (%u of nested tasks)\n",
        call.name, faults, faults_elsewhere, tasks, nested, items, nested_items);
    if (call.on_pool == OnPool::kLoops) {
      if (tasks == 0 || items == 0)
        fail_msg("%s: no loop ran in blocks on the pool's threads (%u tasks, %u items on the pool)",
                 call.name, tasks, items);
    } else if (faults_elsewhere == 0 || nested == 0 || nested_items == 0) {
      fail_msg(
          "%s: the step's failures on a pool thread (%ld) or its loops as nested tasks (%u, %u items on the "
          "pool's threads) were not reached",
          call.name, faults_elsewhere, nested, nested_items);
    }
  }

  // After every failure the world goes on exactly like a world that never saw one.
  if (call.changes_world) {
    Scene reference;
    call.build(&reference);
    assert_int_equal(call.run(&reference), SPH_OK);
    EXPECT_OK(sph_world_step(scene.world, scene.frame_dt));
    EXPECT_OK(sph_world_step(reference.world, reference.frame_dt));
    // The simulated time and the particles, bitwise.
    particles_of(scene.world, &particles_now);
    particles_of(reference.world, &particles_before);
    expect_same_bytes(call.name, -1, "particles (against the undisturbed world)", particles_before,
                      particles_now);
    uint32_t count = 0;
    EXPECT_OK(sph_world_get_particle_count(scene.world, &count));
    if (count <= CAPI_SNAPSHOT_MAX) {
      capi_snapshot_take(reference.world, &g_reference);
      EXPECT_UNCHANGED(scene.world, &g_reference);
    }
    // The readings, loads, events and the step's statistics too, and the checkpoint's size (its
    // bytes hold the steps' wall times): no object a failure added or lost.
    readouts_of(&scene, &readouts_now);
    readouts_of(&reference, &readouts_before);
    expect_same_bytes(call.name, -1, "readings, loads, events or statistics (against the undisturbed world)",
                      readouts_before, readouts_now);
    checkpoint_of(&scene, &checkpoint_now);
    checkpoint_of(&reference, &checkpoint_before);
    if (checkpoint_now.size() != checkpoint_before.size())
      fail_msg("%s: the checkpoint has %zu bytes, the undisturbed world's %zu", call.name,
               checkpoint_now.size(), checkpoint_before.size());
    destroy_scene(&reference);
  }
  destroy_scene(&scene);
}

void test_every_call(void**) {
  for (const Call& call : kCalls) check_call(call);
  // The asynchronous steps of the task-system calls ran as tasks of the pool. (The small tank's 226
  // particles make each loop one block, which the library runs on the calling thread without a
  // task; the large tank's calls check their loops' tasks themselves: OnPool.)
  printf("the engine's task system: %u tasks on the pool, %u of them nested\n", task_pool_tasks(),
         task_pool_nested());
  assert_true(task_pool_tasks() > 0);
}

// The injector itself: armed at 0, the very next allocation fails.
void test_injector_works(void**) {
  arm(0);
  bool threw = false;
  try {
    // A direct call: a new-expression whose result is unused may be optimised away.
    void* p = ::operator new(16);
    ::operator delete(p);
  } catch (const std::bad_alloc&) {
    threw = true;
  }
  assert_true(disarm());
  assert_true(threw);
  void* p = ::operator new(16);
  assert_non_null(p);
  ::operator delete(p);
}

// Whether the library's allocations reach this executable's operator new: not when libsph carries
// its own copy of the C++ runtime (a toolchain that links libstdc++ statically, as the GPU
// machine's /opt/gcc does: its operator new is then local to libsph.so). The test then cannot
// inject anything, and says so rather than passing with no allocation point failed.
bool library_allocations_reach_the_injector() {
  sph_context_def cdef;
  sph_context_def_init(&cdef);
  cdef.backend = SPH_BACKEND_CPU;
  sph_context* context = nullptr;
  arm(0);
  const sph_result r = sph_context_create(&cdef, &context);
  const bool injected = disarm();
  if (r == SPH_OK) sph_context_destroy(context);
  return injected;
}

}  // namespace

int main(void) {
  if (!library_allocations_reach_the_injector()) {
    fprintf(stderr,
            "SKIP: libsph's allocations do not reach this executable's operator new (is the C++ runtime "
            "linked into libsph statically? readelf -d libsph.so lists no libstdc++): nothing can be "
            "injected\n");
    return 77;
  }
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_injector_works),
      cmocka_unit_test(test_every_call),
  };
  const char* fresh = getenv("SPH_TEST_FRESH_SCENES");
  g_fresh_scenes = fresh && strcmp(fresh, "1") == 0;
  // The checkpoint files' folder, empty again at the end.
  const char* tmp = getenv("TMPDIR");
  g_checkpoint_folder = std::string(tmp && *tmp ? tmp : "/tmp") + "/sph_allocation_failure.XXXXXX";
  if (!mkdtemp(&g_checkpoint_folder[0])) {
    perror("mkdtemp");
    return 1;
  }
  g_checkpoint_file = g_checkpoint_folder + "/world.sphcp";
  task_pool_start();  // (its threads exist before any allocation is armed)
  const int failed = cmocka_run_group_tests(tests, nullptr, nullptr);
  task_pool_stop();
  unlink(g_checkpoint_file.c_str());  // (left by a failed case)
  rmdir(g_checkpoint_folder.c_str());
  return failed;
}
