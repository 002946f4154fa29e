// SPDX-License-Identifier: MIT
// Host allocation failures (issue 9, item 6), injected at every allocation point of every
// call in turn.
//
// This executable replaces the global operator new (tests/support/allocation_injector.h; libsph
// resolves it from the executable, since the library exports nothing but sph_*). Armed with n, the n-th
// allocation from then on throws std::bad_alloc (or returns null for the nothrow forms), once. For each call
// below, n runs 0, 1, 2, ... until the call completes without reaching the n-th allocation, so every
// allocation the call makes fails once. Each failure must come back as
// SPH_ERROR_OUT_OF_HOST_MEMORY with a message, leave the world bitwise as it was and the live
// object count unchanged, and the world must then go on exactly as an undisturbed copy.
//
// It runs through the C API on the backend SPH_TEST_BACKEND names, so scripts/gpu-test runs it
// on the CUDA backend too (host allocations of the CUDA backend: staging, scene uploads, ...).
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <atomic>
#include <cstddef>
#include <new>

extern "C" {
#include "capi_test.h"
}
#include "allocation_injector.h"

using alloc_fault::arm;
using alloc_fault::disarm;

// ---- the scene every call runs against ----------------------------------------------------------
namespace {

constexpr uint32_t kCapacity = CAPI_SNAPSHOT_MAX;
constexpr float kFrameDt = 1.0f / 60.0f;

struct Scene {
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  sph_sdf* tank = nullptr;  // kept, so calls can create more colliders, sources and sinks
  sph_sdf* blob = nullptr;
};

sph_transform at(float x, float y, float z) {
  sph_transform t = sph_transform_identity();
  t.position.x = x;
  t.position.y = y;
  t.position.z = z;
  return t;
}

// A tank with a sloshing block of water, a continuous source, a sink and a force field, one
// frame behind it: every part of a frame has state to roll back.
void build_scene(Scene* s) {
  sph_context_def cdef;
  EXPECT_OK(sph_test_context_def_init(&cdef));
  cdef.cpu_worker_count = 1;
  EXPECT_OK(sph_context_create(&cdef, &s->context));
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = kCapacity;
  def.particle_spacing = 0.025f;
  EXPECT_OK(sph_world_create(s->context, &def, &s->world));
  sph_world_params params;
  sph_world_params_init(&params);
  params.gravity.x = 2.0f;
  params.max_substeps = 100;
  EXPECT_OK(sph_world_set_params(s->world, &params));

  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents = sph_vec3{0.2f, 0.2f, 0.1f};
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
  sph_collider_id collider_id;
  EXPECT_OK(sph_collider_create(s->world, &collider, &collider_id));

  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.min = sph_vec3{-0.18f, -0.18f, -0.08f};
  box.max = sph_vec3{-0.05f, 0.0f, 0.08f};
  uint32_t filled = 0;
  EXPECT_OK(sph_world_fill_box(s->world, &box, &filled));
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

  EXPECT_OK(sph_world_step(s->world, kFrameDt));
}

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

// ---- the calls ----------------------------------------------------------------------------------
// Each runs one call against the scene; objects it creates on success are released by `undo`
// (which runs unarmed).
struct Call {
  const char* name;
  sph_result (*run)(Scene*);
  void (*undo)(Scene*);
  bool changes_world;  // on success: the scene is rebuilt for the next call
};

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

sph_result run_step(Scene* s) { return sph_world_step(s->world, kFrameDt); }

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

void no_undo(Scene*) {}

const Call kCalls[] = {
    {"sph_context_create", run_context_create, undo_context_create, false},
    {"sph_world_create", run_world_create, undo_world_create, false},
    {"sph_sdf_create_shape", run_sdf_create_shape, undo_sdf, false},
    {"sph_world_fill_box", run_fill_box, no_undo, true},
    {"sph_world_fill_sphere", run_fill_sphere, no_undo, true},
    {"sph_world_spawn", run_spawn, no_undo, true},
    {"sph_world_set_params", run_set_params, no_undo, true},
    {"sph_collider_create", run_collider_create, no_undo, true},
    {"sph_source_create", run_source_create, no_undo, true},
    {"sph_sink_create", run_sink_create, no_undo, true},
    {"sph_force_field_create", run_force_field_create, no_undo, true},
    {"sph_world_step", run_step, no_undo, true},
    {"copy_attribute + get_stats + get_events", run_copy_and_stats, no_undo, false},
};

capi_snapshot g_before;
capi_snapshot g_after_fault;
capi_snapshot g_reference;

void check_call(const Call& call) {
  Scene scene;
  build_scene(&scene);
  long faults = 0;
  for (long n = 0;; ++n) {
    capi_snapshot_take(scene.world, &g_before);
    const uint32_t objects_before = live_objects();
    arm(n);
    const sph_result r = call.run(&scene);
    const bool injected = disarm();
    if (!injected) {
      // The call made fewer than n + 1 allocations: it ran to the end.
      if (r != SPH_OK)
        fail_msg("%s without a fault: %s (%s)", call.name, sph_result_string(r), sph_get_last_error());
      call.undo(&scene);
      break;
    }
    ++faults;
    if (r == SPH_OK) {
      // The library absorbed the failure (a fallback that does not need the memory): the call
      // must still have done its whole job, which the next iterations cannot tell apart from a
      // clean run; start again from a fresh scene so the remaining allocation points are reached
      // from the same state.
      call.undo(&scene);
      destroy_scene(&scene);
      build_scene(&scene);
      continue;
    }
    if (r != SPH_ERROR_OUT_OF_HOST_MEMORY)
      fail_msg("%s with allocation %ld failing returned %s (%s), not SPH_ERROR_OUT_OF_HOST_MEMORY", call.name,
               n, sph_result_string(r), sph_get_last_error());
    if (strstr(sph_get_last_error(), "alloc") == nullptr && strstr(sph_get_last_error(), "memory") == nullptr)
      fail_msg("%s: the message does not say what ran out: '%s'", call.name, sph_get_last_error());
    if (live_objects() != objects_before)
      fail_msg("%s with allocation %ld failing leaked a handle", call.name, n);
    EXPECT_UNCHANGED(scene.world, &g_before);
  }
  print_message("%-40s %ld allocation points failed once each\n", call.name, faults);

  // After every failure the world goes on exactly like a world that never saw one.
  if (call.changes_world) {
    Scene reference;
    build_scene(&reference);
    assert_int_equal(call.run(&reference), SPH_OK);
    EXPECT_OK(sph_world_step(scene.world, kFrameDt));
    EXPECT_OK(sph_world_step(reference.world, kFrameDt));
    capi_snapshot_take(scene.world, &g_after_fault);
    capi_snapshot_take(reference.world, &g_reference);
    // The simulated time and the particles, bitwise.
    EXPECT_UNCHANGED(scene.world, &g_reference);
    destroy_scene(&reference);
  }
  destroy_scene(&scene);
}

void test_every_call(void**) {
  for (const Call& call : kCalls) check_call(call);
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

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_injector_works),
      cmocka_unit_test(test_every_call),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
