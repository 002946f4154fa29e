// SPDX-License-Identifier: MIT
/* What one call may cost (issue 23 item 9), on the CPU backend: a world of capacity 2^30 with
 * 100 particles does not allocate a capacity-sized cell table; particles piled into one cell
 * are refused at once instead of costing time quadratic in their number; a step budget and a
 * cancel from another thread stop a step at a substep boundary (INCOMPLETE, the world
 * consistent: it saves, loads and steps on); max_substeps is bounded.
 *
 * Part of the hostile-input suite: ctest label `hostile`. */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "capi_test.h"

static double now_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Under ThreadSanitizer one worker: libgomp is not instrumented, so the OpenMP reductions of a
 * multi-worker step would be reported as races. The cancel still comes from another thread. */
static sph_context* cpu_context(void) {
  sph_context* context = NULL;
  sph_context_def def;
  EXPECT_OK(sph_test_context_def_init(&def));
  def.backend = SPH_BACKEND_CPU;
#ifdef SPH_TEST_TSAN_BUILD
  def.cpu_worker_count = 1;
#endif
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

static sph_world* make_world(sph_context* context, uint32_t capacity) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_def_init(&def);
  def.capacity = capacity;
  EXPECT_OK(sph_world_create(context, &def, &world));
  return world;
}

/* count particles at one point (all of them) or on a line 1 km long (spread). */
static void spawn(sph_world* world, uint32_t count, int spread) {
  sph_spawn_desc d;
  float* p = (float*)calloc(3u * count, sizeof(float));
  uint32_t i, first = 0;
  assert_non_null(p);
  for (i = 0; i < count; ++i) {
    p[3 * i] = spread ? 1000.0f * (float)i / (float)count : 0.25f;
    p[3 * i + 1] = 0.5f;
    p[3 * i + 2] = spread ? -7.0f * (float)(i % 10) : 0.125f;
  }
  sph_spawn_desc_init(&d);
  d.count = count;
  d.positions = p;
  EXPECT_OK(sph_world_spawn(world, &d, &first));
  free(p);
}

/* A world of capacity 2^30 (the most a def may ask for) with 100 particles steps within a few
 * megabytes: the CPU backend's cell table follows the particles (before: 2^30 slots, 4 GiB at
 * the first step). */
static void test_huge_capacity_few_particles(void** state) {
  sph_context* context = cpu_context();
  sph_world* world = make_world(context, 1u << 30);
  sph_stats stats;
  (void)state;
  spawn(world, 100, 1);
  EXPECT_OK(sph_world_step(world, 1.0f / 60.0f));
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  printf("capacity 2^30, 100 particles: %llu bytes after a step\n", (unsigned long long)stats.memory_bytes);
  assert_true(stats.memory_bytes < (1u << 20));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* The cap of one cell: 64 times a cell of fluid at rest, sqrt(2) (h/s)^3 (cpu_neighbor_grid.h). */
static uint32_t cell_cap(const sph_world* world) {
  sph_world_def def;
  double ratio;
  sph_world_def_init(&def);
  EXPECT_OK(sph_world_get_def(world, &def));
  ratio = (double)def.kernel_radius / (double)def.particle_spacing;
  return (uint32_t)ceil(64.0 * sqrt(2.0) * ratio * ratio * ratio);
}

/* 16,000 particles at one point (the case: 45 s a frame, quadratic) are refused at the
 * first step in well under a second, with CAPACITY, a message that says where, and the world
 * unchanged; one particle more than the cap is refused too, the cap itself steps. */
static void test_coincident_particles_are_refused(void** state) {
  sph_context* context = cpu_context();
  sph_world* world = make_world(context, 16000);
  sph_world* before;
  uint32_t cap;
  double t;
  (void)state;
  spawn(world, 16000, 0);
  before = capi_world_copy(context, world);
  t = now_seconds();
  assert_int_equal(sph_world_step(world, 1.0f / 60.0f), SPH_ERROR_CAPACITY);
  t = now_seconds() - t;
  printf("16,000 coincident particles: refused in %.3f s: %s\n", t, sph_get_last_error());
  assert_true(t < 1.0);
  assert_non_null(strstr(sph_get_last_error(), "16000 particles share one cell"));
  assert_non_null(strstr(sph_get_last_error(), "(0.25"));
  capi_expect_same_particles(world, before);
  EXPECT_OK(sph_world_destroy(before));
  EXPECT_OK(sph_world_destroy(world));

  world = make_world(context, 4096);
  cap = cell_cap(world);
  spawn(world, cap + 1, 0);
  assert_int_equal(sph_world_step(world, 1e-4f), SPH_ERROR_CAPACITY);
  EXPECT_OK(sph_world_destroy(world));
  world = make_world(context, 4096);
  spawn(world, cap, 0);
  /* At the cap the grid accepts them; what the physics makes of coincident particles is not
   * this test's business, only that the step is not refused for the cell. */
  assert_int_not_equal(sph_world_step(world, 1e-4f), SPH_ERROR_CAPACITY);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* A world whose frame needs `substeps` fixed substeps of 1e-4 s (a block of 1,000 particles). */
static sph_world* slow_world(sph_context* context, uint32_t max_substeps) {
  sph_world* world = make_world(context, 4096);
  sph_world_params params;
  sph_fill_box_desc box;
  uint32_t added = 0;
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.2f;
  EXPECT_OK(sph_world_fill_box(world, &box, &added));
  assert_true(added > 500);
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  params.dt_min = params.dt_max = 1e-4f;
  params.max_substeps = max_substeps;
  EXPECT_OK(sph_world_set_params(world, &params));
  return world;
}

static uint32_t substeps_of(const sph_world* world, float* frame_time) {
  sph_stats stats;
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  if (frame_time) *frame_time = stats.frame_time;
  return stats.substeps;
}

/* After an interrupted step the world is consistent: it saves, the save loads, and both step
 * on to the same particles, bit for bit. */
static void expect_consistent(sph_context* context, sph_world* world) {
  sph_world* copy = capi_world_copy(context, world);
  EXPECT_OK(sph_world_step(world, 2e-4f));
  EXPECT_OK(sph_world_step(copy, 2e-4f));
  capi_expect_same_particles(world, copy);
  EXPECT_OK(sph_world_destroy(copy));
}

/* A budget of 50 ms stops a frame of 10,000 substeps early: INCOMPLETE, some substeps done,
 * the time reported is theirs, and the step took about the budget (plus one substep). */
static void test_step_budget(void** state) {
  sph_context* context = cpu_context();
  sph_world* world = slow_world(context, 10000);
  double budget = -1.0, t;
  float frame_time = 0.0f;
  uint32_t substeps;
  (void)state;
  EXPECT_OK(sph_world_get_step_budget(world, &budget));
  assert_true(budget == 0.0);
  EXPECT_OK(sph_world_set_step_budget(world, 0.05));
  EXPECT_OK(sph_world_get_step_budget(world, &budget));
  assert_true(budget == 0.05);
  t = now_seconds();
  assert_int_equal(sph_world_step(world, 1.0f), SPH_INCOMPLETE);
  t = now_seconds() - t;
  substeps = substeps_of(world, &frame_time);
  printf("budget 0.05 s: stopped after %u substeps, %.4f s simulated, in %.3f s\n", substeps, frame_time, t);
  assert_true(substeps >= 1 && substeps < 10000);
  assert_true(fabs(frame_time - 1e-4f * (float)substeps) < 1e-4f * (float)substeps * 1e-3f);
  assert_true(t < 0.05 + 2.0); /* the budget, one substep and a loaded machine's slack */
  EXPECT_OK(sph_world_set_step_budget(world, 0.0));
  expect_consistent(context, world);
  /* Refused budgets name the argument and change nothing. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "max_seconds", sph_world_set_step_budget(world, -1.0));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "max_seconds", sph_world_set_step_budget(world, NAN));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "max_seconds", sph_world_set_step_budget(world, 1e9));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_seconds", sph_world_get_step_budget(world, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_set_step_budget(NULL, 1.0));
  EXPECT_OK(sph_world_get_step_budget(world, &budget));
  assert_true(budget == 0.0);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

typedef struct canceller {
  sph_world* world;
  useconds_t delay_us;
  sph_result result;
} canceller;

static void* cancel_later(void* arg) {
  canceller* c = (canceller*)arg;
  usleep(c->delay_us);
  c->result = sph_world_cancel_step(c->world);
  return NULL;
}

/* A cancel before the step: INCOMPLETE at once, 0 substeps, nothing changed; the next step runs
 * whole (the request was used up). A cancel from another thread 50 ms into a step of 10,000
 * substeps stops it early, and never answers WORLD_LOCKED. */
static void test_cancel(void** state) {
  sph_context* context = cpu_context();
  sph_world* world = slow_world(context, 10000);
  sph_world* before;
  canceller c;
  pthread_t thread;
  double t;
  uint32_t substeps;
  (void)state;
  before = capi_world_copy(context, world);
  EXPECT_OK(sph_world_cancel_step(world));
  assert_int_equal(sph_world_step(world, 1.0f), SPH_INCOMPLETE);
  assert_int_equal(substeps_of(world, NULL), 0);
  capi_expect_same_particles(world, before);
  EXPECT_OK(sph_world_destroy(before));
  EXPECT_OK(sph_world_step(world, 2e-4f));
  assert_int_equal(substeps_of(world, NULL), 2);

  c.world = world;
  c.delay_us = 50000;
  c.result = SPH_ERROR_INTERNAL;
  assert_int_equal(pthread_create(&thread, NULL, cancel_later, &c), 0);
  t = now_seconds();
  assert_int_equal(sph_world_step(world, 1.0f), SPH_INCOMPLETE);
  t = now_seconds() - t;
  assert_int_equal(pthread_join(thread, NULL), 0);
  substeps = substeps_of(world, NULL);
  printf("cancelled from another thread after 50 ms: %u substeps, %.3f s\n", substeps, t);
  assert_int_equal(c.result, SPH_OK);
  assert_true(substeps >= 1 && substeps < 10000);
  expect_consistent(context, world);

  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_cancel_step(NULL));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_cancel_step(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* max_substeps is at most 1,000,000 (100 times the default): 2^32 - 1 let one step run for
 * hours. */
static void test_max_substeps_is_bounded(void** state) {
  sph_context* context = cpu_context();
  sph_world* world = make_world(context, 64);
  sph_world_params params;
  (void)state;
  sph_world_params_init(&params);
  params.max_substeps = 1000000;
  EXPECT_OK(sph_world_set_params(world, &params));
  params.max_substeps = 1000001;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "max_substeps", sph_world_set_params(world, &params));
  params.max_substeps = UINT32_MAX;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "max_substeps", sph_world_set_params(world, &params));
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  assert_int_equal(params.max_substeps, 1000000);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_huge_capacity_few_particles),
      cmocka_unit_test(test_coincident_particles_are_refused),
      cmocka_unit_test(test_step_budget),
      cmocka_unit_test(test_cancel),
      cmocka_unit_test(test_max_substeps_is_bounded),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
