// SPDX-License-Identifier: MIT
/* Growable worlds (issue 19 item 1): sph_world_def.max_capacity lets a world's capacity grow on
 * demand. What is asserted:
 * - the def: max_capacity 0 is a fixed world (today's behaviour), a bad value is refused naming
 *   the field, an older caller's def (44 bytes, before the field) still creates a world;
 * - growth is geometric (max(needed, 2 x capacity), clamped to max_capacity) and reported
 *   (sph_stats.capacity, capacity_growths, sph_world_get_def);
 * - a world that grew holds, after the same steps, bit for bit the particles of a world created
 *   at the larger capacity (on both backends when the growth comes before the first step; on
 *   the CPU also when it comes between steps, since the CPU's grid never depends on capacity);
 * - a source emitting past the capacity grows the world (SPH_EVENT_CAPACITY_GROWN) up to
 *   max_capacity, then emits what fits (SPH_EVENT_SOURCE_CAPACITY_REACHED);
 * - past max_capacity a spawn or fill is refused with SPH_ERROR_CAPACITY, a message naming the
 *   limit, and the world unchanged;
 * - a failed step on a grown world rolls back, and the world then steps like a copy;
 * - a grown world's checkpoint restores its capacity and max_capacity and steps on bit for bit
 *   (weakly compressible and DFSPH, grown between steps);
 * - a DFSPH world grown before its first step steps as a world created at its capacity (its
 *   capacity-strided arrays, such as the CUDA neighbour lists of SPH_TEST_CUDA_DFSPH_MASKS=lists,
 *   reallocated with it).
 * Runs on SPH_TEST_BACKEND (cpu by default; the lead runs it with cuda on the GPU machine). */
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

#define SPACING 0.05f
#define FRAME (1.0f / 120.0f)

static sph_stats stats_of(const sph_world* world) {
  sph_stats s;
  sph_stats_init(&s);
  EXPECT_OK(sph_world_get_stats(world, &s));
  return s;
}

static sph_world* make_solver_world(sph_context* context, uint32_t capacity, uint32_t max_capacity,
                                    sph_solver solver) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.max_capacity = max_capacity;
  def.solver = solver;
  def.particle_spacing = SPACING;
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(support_set_gravity_and_steps(world, 0.0f, -9.81f, 0.0f, 1e-5f, 2e-3f));
  return world;
}

static sph_world* make_world(sph_context* context, uint32_t capacity, uint32_t max_capacity) {
  return make_solver_world(context, capacity, max_capacity, SPH_SOLVER_WCSPH);
}

/* A block of FCC points `layers` wide with its corner at (x, 0, 0), moving in x at `speed` (so
 * the batches collide and the steps have work to do). */
static void spawn_block(sph_world* world, uint32_t layers, float x, float speed) {
  const uint32_t l[3] = {layers, layers, layers};
  const double origin[3] = {x, 0.0, 0.0};
  float* positions = NULL;
  float* velocities;
  uint32_t count = 0, i;
  assert_int_equal(support_fcc_box(l, SPACING / 1.41421356, origin, &positions, &count), SPH_OK);
  velocities = (float*)calloc(3u * count, sizeof(float));
  assert_non_null(velocities);
  for (i = 0; i < count; ++i) velocities[3 * i] = speed;
  EXPECT_OK(support_spawn(world, positions, velocities, count));
  free(positions);
  free(velocities);
}

static uint32_t block_count(uint32_t layers) {
  const uint32_t l[3] = {layers, layers, layers};
  float* positions = NULL;
  uint32_t count = 0;
  assert_int_equal(support_fcc_box(l, SPACING / 1.41421356, NULL, &positions, &count), SPH_OK);
  free(positions);
  return count;
}

static void steps(sph_world* world, int n) {
  int k;
  for (k = 0; k < n; ++k) EXPECT_OK(sph_world_step(world, FRAME));
}

static void test_def_defaults_and_refusals(void** state) {
  sph_context* context = NULL;
  sph_world_def def, got;
  sph_world* world = NULL;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  assert_int_equal(def.max_capacity, 0); /* zero means default: a fixed world */
  def.capacity = 100;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_def_init(&got);
  EXPECT_OK(sph_world_get_def(world, &got));
  assert_int_equal(got.capacity, 100);
  assert_int_equal(got.max_capacity, 100);
  assert_int_equal(stats_of(world).capacity, 100);
  assert_int_equal(stats_of(world).max_capacity, 100);
  assert_int_equal(stats_of(world).capacity_growths, 0);
  EXPECT_OK(sph_world_destroy(world));
  world = NULL;

  def.max_capacity = 99; /* below the capacity */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->max_capacity", sph_world_create(context, &def, &world));
  def.max_capacity = (1u << 30) + 1u;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->max_capacity", sph_world_create(context, &def, &world));
  assert_null(world);
  /* The default capacity (0 = 65536) with a larger maximum. */
  def.capacity = 0;
  def.max_capacity = 1u << 30;
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(sph_world_get_def(world, &got));
  assert_int_equal(got.capacity, 65536);
  assert_int_equal(got.max_capacity, 1u << 30);
  EXPECT_OK(sph_world_destroy(world));
  world = NULL;

  /* A caller built before max_capacity (a 44-byte def, 0.2.0 with the solver): a fixed world. */
  sph_world_def_init(&def);
  def.capacity = 50;
  def.struct_size = (uint32_t)offsetof(sph_world_def, max_capacity);
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(sph_world_get_def(world, &got));
  assert_int_equal(got.max_capacity, 50);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* Three spawns grow 64 -> 128 -> 256 -> 512 (geometric); the grown world then steps bit for bit
 * like a world created at 512 that got the same spawns. */
static void test_spawn_grows_like_a_larger_world(void** state) {
  sph_context* context = NULL;
  sph_world *grown, *large;
  const uint32_t b3 = block_count(3), b4 = block_count(4), b5 = block_count(5);
  sph_stats s;
  sph_world_def def;
  (void)state;
  /* Of 27, 64 and 125 simple-cubic points those with an even index sum. */
  assert_int_equal(b3, 14);
  assert_int_equal(b4, 32);
  assert_int_equal(b5, 63);
  EXPECT_OK(sph_test_context_create(&context));
  grown = make_world(context, 8, 4096);
  spawn_block(grown, 3, 0.0f, 0.5f);
  s = stats_of(grown);
  assert_int_equal(s.capacity, 16); /* 14 > 8: max(14, 2 x 8) */
  assert_int_equal(s.capacity_growths, 1);
  spawn_block(grown, 4, 0.3f, -0.5f);
  s = stats_of(grown);
  assert_int_equal(s.capacity, 46); /* 46 > 32 = 2 x 16 */
  spawn_block(grown, 5, -0.4f, 0.25f);
  s = stats_of(grown);
  assert_int_equal(s.particle_count, b3 + b4 + b5);
  assert_int_equal(s.capacity, 109); /* 109 > 92 = 2 x 46 */
  assert_int_equal(s.capacity_growths, 3);
  sph_world_def_init(&def);
  EXPECT_OK(sph_world_get_def(grown, &def));
  assert_int_equal(def.capacity, 109);
  assert_int_equal(def.max_capacity, 4096);

  large = make_world(context, s.capacity, 0);
  spawn_block(large, 3, 0.0f, 0.5f);
  spawn_block(large, 4, 0.3f, -0.5f);
  spawn_block(large, 5, -0.4f, 0.25f);
  steps(grown, 6);
  steps(large, 6);
  capi_expect_same_particles(grown, large);
  /* One more particle in a full world doubles it. */
  spawn_block(grown, 1, 2.0f, 0.0f);
  s = stats_of(grown);
  assert_int_equal(s.capacity, 218);
  assert_int_equal(s.capacity_growths, 4);
  EXPECT_OK(sph_world_destroy(grown));
  EXPECT_OK(sph_world_destroy(large));
  EXPECT_OK(sph_context_destroy(context));
}

/* The same with DFSPH: three batches grow the world to 109 slots, then six frames against a world
 * created at 109 (the solves' iterations too: the same bits). */
static void test_dfsph_grows_like_a_larger_world(void** state) {
  sph_context* context = NULL;
  sph_world *grown, *large;
  sph_stats g, l;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  grown = make_solver_world(context, 8, 4096, SPH_SOLVER_DFSPH);
  large = make_solver_world(context, 109, 0, SPH_SOLVER_DFSPH);
  spawn_block(grown, 3, 0.0f, 0.5f);
  spawn_block(grown, 4, 0.3f, -0.5f);
  spawn_block(grown, 5, -0.4f, 0.25f);
  spawn_block(large, 3, 0.0f, 0.5f);
  spawn_block(large, 4, 0.3f, -0.5f);
  spawn_block(large, 5, -0.4f, 0.25f);
  assert_int_equal(stats_of(grown).capacity, 109);
  assert_int_equal(stats_of(grown).capacity_growths, 3);
  steps(grown, 6);
  steps(large, 6);
  g = stats_of(grown);
  l = stats_of(large);
  assert_true(g.pressure_iterations > 0); /* the solves ran */
  assert_int_equal(g.pressure_iterations, l.pressure_iterations);
  assert_int_equal(g.divergence_iterations, l.divergence_iterations);
  capi_expect_same_particles(grown, large);
  EXPECT_OK(sph_world_destroy(grown));
  EXPECT_OK(sph_world_destroy(large));
  EXPECT_OK(sph_context_destroy(context));
}

/* Growth between steps (CPU: its neighbour grid is sized from the particles, never from the
 * capacity, so the capacity history cannot change a result; the CUDA grid is sized from the
 * capacity, and the checkpoint test below covers its growth mid-run). */
static void test_growth_between_steps_changes_nothing(void** state) {
  sph_context* context = NULL;
  sph_world *grown, *large;
  (void)state;
  if (sph_test_backend() != SPH_BACKEND_CPU) skip();
  EXPECT_OK(sph_test_context_create(&context));
  grown = make_world(context, 16, 1024);
  large = make_world(context, 1024, 0);
  spawn_block(grown, 3, 0.0f, 0.5f);
  spawn_block(large, 3, 0.0f, 0.5f);
  steps(grown, 3);
  steps(large, 3);
  spawn_block(grown, 5, 0.4f, -0.5f);
  spawn_block(large, 5, 0.4f, -0.5f);
  assert_int_equal(stats_of(grown).capacity, 77); /* 14 + 63 > 32 */
  steps(grown, 3);
  steps(large, 3);
  capi_expect_same_particles(grown, large);
  EXPECT_OK(sph_world_destroy(grown));
  EXPECT_OK(sph_world_destroy(large));
  EXPECT_OK(sph_context_destroy(context));
}

static uint32_t count_events(const sph_world* world, sph_event_type type, uint32_t* last_count) {
  sph_event events[16];
  uint32_t n = 0, i, found = 0;
  EXPECT_OK(sph_world_get_events(world, events, 16, &n));
  for (i = 0; i < n; ++i)
    if (events[i].type == type) {
      ++found;
      if (last_count) *last_count = events[i].count;
    }
  return found;
}

/* A continuous source in a world of capacity 32: the first step grows it for the emission, and
 * emission continues until max_capacity, where the source reports what did not fit. */
static void test_source_grows_the_world(void** state) {
  sph_context* context = NULL;
  sph_world *grown, *large;
  sph_shape_desc shape;
  sph_source_def source;
  sph_sdf* region = NULL;
  sph_source_id id;
  uint32_t count = 0, emitted, reported = 0, capacity, grown_to = 0;
  int k;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  grown = make_world(context, 32, 300);
  large = make_world(context, 300, 0);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.12f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &region));
  sph_source_def_init(&source);
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.region = region;
  source.velocity.y = -2.0f;
  EXPECT_OK(sph_source_create(grown, &source, &id));
  EXPECT_OK(sph_source_create(large, &source, &id));
  EXPECT_OK(sph_sdf_destroy(region));

  EXPECT_OK(sph_world_step(grown, FRAME));
  EXPECT_OK(sph_world_step(large, FRAME));
  EXPECT_OK(sph_world_get_particle_count(grown, &emitted));
  assert_true(emitted > 32); /* the sphere holds about 4/3 pi 0.12^3 sqrt2 / 0.05^3 = 82 points */
  assert_int_equal(count_events(grown, SPH_EVENT_CAPACITY_GROWN, &reported), 1);
  assert_int_equal(reported, stats_of(grown).capacity);
  assert_int_equal(reported, emitted > 64 ? emitted : 64);
  assert_int_equal(count_events(large, SPH_EVENT_CAPACITY_GROWN, NULL), 0);
  /* Emission goes on until max_capacity holds back part of one: the source says how many. */
  reported = 0;
  capacity = stats_of(grown).capacity;
  for (k = 0; k < 200 && count_events(grown, SPH_EVENT_SOURCE_CAPACITY_REACHED, &reported) == 0; ++k) {
    EXPECT_OK(sph_world_step(grown, FRAME));
    EXPECT_OK(sph_world_step(large, FRAME));
    EXPECT_OK(sph_world_get_particle_count(grown, &count));
    if (stats_of(grown).capacity != capacity) { /* the rule: max(needed, 2 x capacity) up to the maximum */
      const uint32_t doubled = count > 2 * capacity ? count : 2 * capacity;
      capacity = stats_of(grown).capacity;
      assert_int_equal(capacity, doubled < 300 ? doubled : 300);
      assert_int_equal(count_events(grown, SPH_EVENT_CAPACITY_GROWN, &grown_to), 1);
      assert_int_equal(grown_to, capacity);
    }
  }
  assert_true(reported > 0);
  EXPECT_OK(sph_world_get_particle_count(grown, &count));
  assert_int_equal(count, 300); /* filled to max_capacity exactly */
  assert_int_equal(stats_of(grown).capacity, 300);
  /* On the CPU the capacity history changes nothing (see above): bit for bit the fixed world. */
  if (sph_test_backend() == SPH_BACKEND_CPU) capi_expect_same_particles(grown, large);
  EXPECT_OK(sph_world_destroy(grown));
  EXPECT_OK(sph_world_destroy(large));
  EXPECT_OK(sph_context_destroy(context));
}

/* Past max_capacity: SPH_ERROR_CAPACITY naming the limit, the world (capacity included) as it was. */
static void test_max_capacity_refused(void** state) {
  static capi_snapshot before;
  sph_context* context = NULL;
  sph_world *world, *fixed;
  sph_fill_box_desc box;
  float positions[3 * 101];
  uint32_t i;
  (void)state;
  for (i = 0; i < 101; ++i) {
    positions[3 * i] = SPACING * (float)(i % 10);
    positions[3 * i + 1] = SPACING * (float)(i / 10);
    positions[3 * i + 2] = 0.0f;
  }
  EXPECT_OK(sph_test_context_create(&context));
  world = make_world(context, 16, 100);
  capi_snapshot_take(world, &before);
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "max_capacity 100", support_spawn(world, positions, NULL, 101));
  EXPECT_UNCHANGED(world, &before);
  assert_int_equal(stats_of(world).capacity, 16);
  assert_int_equal(stats_of(world).capacity_growths, 0);
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 1.0f; /* thousands of points */
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "max_capacity 100", sph_world_fill_box(world, &box, NULL));
  EXPECT_UNCHANGED(world, &before);
  /* Exactly the maximum fits. */
  EXPECT_OK(support_spawn(world, positions, NULL, 100));
  assert_int_equal(stats_of(world).capacity, 100);
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "max_capacity 100", support_spawn(world, positions, NULL, 1));
  /* A fixed world's message says how to make it grow. */
  fixed = make_world(context, 16, 0);
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "a fixed world", support_spawn(fixed, positions, NULL, 17));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_world_destroy(fixed));
  EXPECT_OK(sph_context_destroy(context));
}

/* A step that fails (pressure overflow) on a world whose source grew it in that very step: the
 * particles are back as before the step, the storage keeps its capacity (growth changes no
 * particle), and the world then steps bit for bit like a copy taken before the failed step. */
static void test_rollback_on_grown_world(void** state) {
  sph_context* context = NULL;
  sph_world *world, *copy;
  sph_world_params params, bomb;
  sph_shape_desc shape;
  sph_source_def source;
  sph_sdf* region = NULL;
  sph_source_id id;
  float cluster[9 * 3];
  uint32_t before_count = 0, after_count = 0, i;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  world = make_world(context, 8, 2048);
  spawn_block(world, 3, 0.0f, 0.0f);
  assert_int_equal(stats_of(world).capacity_growths, 1);
  steps(world, 2);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.12f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &region));
  sph_source_def_init(&source);
  source.region = region;
  source.transform.position.y = 1.0f;
  EXPECT_OK(sph_source_create(world, &source, &id)); /* fill once, on the next step */
  EXPECT_OK(sph_sdf_destroy(region));
  /* Nine particles within 1 mm: with k = 3e38 their pressure overflows in the first substep. */
  for (i = 0; i < 9; ++i) {
    cluster[3 * i] = 2.0f + 1e-4f * (float)(i % 3);
    cluster[3 * i + 1] = 1e-4f * (float)(i / 3);
    cluster[3 * i + 2] = 1e-4f * (float)i;
  }
  EXPECT_OK(support_spawn(world, cluster, NULL, 9));
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  copy = capi_world_copy(context, world);
  EXPECT_OK(sph_world_get_particle_count(world, &before_count));
  bomb = params;
  bomb.stiffness = 3e38f;
  EXPECT_OK(sph_world_set_params(world, &bomb));
  EXPECT_ERROR(SPH_ERROR_NON_FINITE, "non-finite", sph_world_step(world, FRAME));
  EXPECT_OK(sph_world_get_particle_count(world, &after_count));
  assert_int_equal(after_count, before_count);
  capi_expect_same_particles(world, copy);
  /* The source grew the world for its emission before the substep failed: the capacity stays. */
  assert_true(stats_of(world).capacity > stats_of(copy).capacity);
  /* Without the overflow both emit the same particles and step alike. */
  EXPECT_OK(sph_world_set_params(world, &params));
  EXPECT_OK(sph_world_step(world, 0.001f));
  EXPECT_OK(sph_world_step(copy, 0.001f));
  assert_int_equal(stats_of(world).capacity, stats_of(copy).capacity);
  capi_expect_same_particles(world, copy);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_world_destroy(copy));
  EXPECT_OK(sph_context_destroy(context));
}

/* A world that grew between steps saves its capacity and max_capacity; the loaded world is a
 * world created at the grown capacity, steps on bit for bit, and may grow further. */
static void checkpoint_of_grown_world(sph_solver solver) {
  sph_context* context = NULL;
  sph_world *world, *copy;
  sph_world_def a, b;
  sph_stats s;
  EXPECT_OK(sph_test_context_create(&context));
  world = make_solver_world(context, 16, 512, solver);
  spawn_block(world, 3, 0.0f, 0.5f);
  steps(world, 2);
  spawn_block(world, 4, 0.35f, -0.5f); /* 14 + 32 > 32 = 2 x 16: grows between steps */
  steps(world, 2);
  copy = capi_world_copy(context, world);
  sph_world_def_init(&a);
  sph_world_def_init(&b);
  EXPECT_OK(sph_world_get_def(world, &a));
  EXPECT_OK(sph_world_get_def(copy, &b));
  assert_int_equal(a.capacity, 46);
  assert_int_equal(b.capacity, a.capacity);
  assert_int_equal(b.max_capacity, 512);
  capi_expect_same_particles(world, copy);
  steps(world, 3);
  steps(copy, 3);
  capi_expect_same_particles(world, copy);
  /* Both grow alike from there. */
  spawn_block(world, 5, -0.4f, 0.25f);
  spawn_block(copy, 5, -0.4f, 0.25f);
  s = stats_of(copy);
  assert_int_equal(s.capacity, 109);
  assert_int_equal(s.capacity_growths, 1); /* counted since the load */
  steps(world, 2);
  steps(copy, 2);
  capi_expect_same_particles(world, copy);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_world_destroy(copy));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_checkpoint_of_grown_world(void** state) {
  (void)state;
  checkpoint_of_grown_world(SPH_SOLVER_WCSPH);
}

/* The same with DFSPH: growth between steps, after the first frames were captured (on CUDA a
 * graph, and with SPH_TEST_CUDA_DFSPH_MASKS=lists capacity-strided lists), then growth again. */
static void test_checkpoint_of_grown_dfsph_world(void** state) {
  (void)state;
  checkpoint_of_grown_world(SPH_SOLVER_DFSPH);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_def_defaults_and_refusals),
      cmocka_unit_test(test_spawn_grows_like_a_larger_world),
      cmocka_unit_test(test_dfsph_grows_like_a_larger_world),
      cmocka_unit_test(test_growth_between_steps_changes_nothing),
      cmocka_unit_test(test_source_grows_the_world),
      cmocka_unit_test(test_max_capacity_refused),
      cmocka_unit_test(test_rollback_on_grown_world),
      cmocka_unit_test(test_checkpoint_of_grown_world),
      cmocka_unit_test(test_checkpoint_of_grown_dfsph_world),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
