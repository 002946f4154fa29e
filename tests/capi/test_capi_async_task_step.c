// SPDX-License-Identifier: MIT
/* Asynchronous steps on the engine's task system (issue 21, items 1 and 2): a CPU context with
 * sph_context_def's enqueue_task / finish_task runs sph_world_step_begin's frame as one task of
 * it, and the library starts no thread. The task system is the tests' own (task_pool.c: three
 * threads started before any context).
 *
 * 1. Two worlds of about 5,800 particles (past the 4,096 where the loops go parallel) begun at
 *    once, two frames: /proc/self/task lists as many threads while the frames run and after
 *    them as before the context; the frames' loops were enqueued from inside the steps' tasks
 *    (nested); each frame ends bit for bit where sph_world_step ends it on the same context.
 * 2. A task system that runs a task itself and returns NULL: begin returns after the frame
 *    (poll says done at once), the wait returns its result, the same bits, no thread (about
 *    1,000 particles: the loops run on the calling thread, so each begin is one task).
 * 3. While the task runs the world answers WORLD_LOCKED (destroy included; its context BUSY),
 *    poll answers and turns to done, cancel reaches the frame; destroy after the wait succeeds.
 * 4. A frame that fails (particles piled into one cell: SPH_ERROR_CAPACITY) reports through the
 *    wait with its message, and the world is as before the begin.
 * In the TSan stage (label threads): with the task system no OpenMP runs, so TSan sees every
 * thread. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "capi_async.h"
#include "task_pool.h"

static const float kFrameDt = 1.0f / 60.0f;
enum { kFrames = 2 };

static sph_context* make_context(void) {
  sph_context_def def;
  sph_context* context = NULL;
  EXPECT_OK(sph_context_def_init(&def));
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 4;
  task_pool_use(&def);
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

/* A block of fluid of side `side` falling in open space: 0.32 m is about 5,800 particles. */
static sph_world* make_world(sph_context* context, float side) {
  uint32_t added = 0;
  sph_world* world = capi_falling_block(context, 8192, side, &added);
  assert_true(side < 0.3f || added > 4096);
  return world;
}

/* 1. The frames are tasks of the pool: no thread, nested loops, sph_world_step's bits. */
static void test_frames_run_as_tasks_and_start_no_thread(void** state) {
  sph_context* context;
  sph_world *a, *b, *reference;
  int before, frame;
  (void)state;
  task_pool_start();
  before = capi_thread_count();
  context = make_context();
  a = make_world(context, 0.32f);
  b = capi_world_copy(context, a);
  reference = capi_world_copy(context, a);
  for (frame = 0; frame < kFrames; ++frame) {
    EXPECT_OK(sph_world_step(reference, kFrameDt));
    EXPECT_OK(sph_world_step_begin(a, kFrameDt));
    EXPECT_OK(sph_world_step_begin(b, kFrameDt));
    assert_int_equal(capi_thread_count(), before);
    /* Done on the pool's threads (poll runs nothing), so the waits below only collect. */
    capi_poll_until_done(a);
    capi_poll_until_done(b);
    assert_int_equal(capi_thread_count(), before);
    EXPECT_OK(sph_world_step_wait(b));
    EXPECT_OK(sph_world_step_wait(a));
    capi_expect_same_particles(a, reference);
    capi_expect_same_particles(b, reference);
  }
  assert_int_equal(capi_thread_count(), before);
  /* Two steps a frame, and the loops of each frame enqueued from inside its task. */
  assert_true(task_pool_tasks() > 2u * kFrames);
  assert_true(task_pool_nested() > 2u * kFrames);
  assert_true(task_pool_items_on_pool() > 2u * kFrames);
  assert_int_equal(task_pool_inline(), 0);
  printf(
      "two worlds, %d frames: %u tasks on the pool, %u of them enqueued from inside a step's task, "
      "%d threads before and after\n",
      kFrames, task_pool_tasks(), task_pool_nested(), before);
  EXPECT_OK(sph_world_destroy(reference));
  EXPECT_OK(sph_world_destroy(b));
  EXPECT_OK(sph_world_destroy(a));
  EXPECT_OK(sph_context_destroy(context));
  task_pool_stop();
}

/* 2. enqueue_task that runs the step itself: begin returns after the frame. */
static void test_inline_enqueue_runs_the_frame_in_begin(void** state) {
  sph_context* context;
  sph_world *world, *reference;
  sph_bool32 done = 0;
  int before, frame;
  (void)state;
  task_pool_start();
  task_pool_set_inline(1);
  before = capi_thread_count();
  context = make_context();
  world = make_world(context, 0.2f);
  reference = capi_world_copy(context, world);
  for (frame = 0; frame < kFrames; ++frame) {
    EXPECT_OK(sph_world_step(reference, kFrameDt));
    EXPECT_OK(sph_world_step_begin(world, kFrameDt));
    EXPECT_OK(sph_world_step_poll(world, &done));
    assert_int_equal(done, 1);
    EXPECT_OK(sph_world_step_wait(world));
    capi_expect_same_particles(world, reference);
  }
  assert_int_equal(capi_thread_count(), before);
  assert_int_equal(task_pool_tasks(), 0);
  assert_int_equal(task_pool_inline(), kFrames); /* one task a begin, run inside it */
  EXPECT_OK(sph_world_destroy(reference));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
  task_pool_stop();
}

/* 3. WORLD_LOCKED, poll and cancel while the task runs; destroy after the wait. */
static void test_pending_task_holds_the_world(void** state) {
  sph_context* context;
  sph_world* world;
  uint32_t count = 0;
  sph_bool32 done = 2;
  int before;
  (void)state;
  task_pool_start();
  before = capi_thread_count();
  context = make_context();
  world = make_world(context, 0.2f); /* about 1,000 particles */
  capi_begin_long_frame_and_expect_held(context, world);
  EXPECT_OK(sph_world_step_poll(world, &done));
  assert_true(done == 0 || done == 1);
  assert_int_equal(capi_thread_count(), before);

  /* 5,001 substeps of about 1e-4 s: the cancel stops the frame early, or, if the frame already
   * ran out, waits for the next step, which then stops at once. */
  capi_expect_cancelled_frame(world, "cancelled frame on the task system");
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "already waited for", sph_world_step_wait(world));
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  assert_true(count > 500);
  assert_int_equal(capi_thread_count(), before);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
  task_pool_stop();
}

/* 4. A failed frame reports through the wait; the world is rolled back. */
static void test_failed_task_reports_through_wait(void** state) {
  sph_context* context;
  (void)state;
  task_pool_start();
  context = make_context();
  capi_expect_failed_step_reported(context);
  EXPECT_OK(sph_context_destroy(context));
  task_pool_stop();
}

int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_frames_run_as_tasks_and_start_no_thread),
      cmocka_unit_test(test_inline_enqueue_runs_the_frame_in_begin),
      cmocka_unit_test(test_pending_task_holds_the_world),
      cmocka_unit_test(test_failed_task_reports_through_wait),
  };
  /* With names, those cases; a name that is no case is an error (exit 2), not a run of none. */
  return capi_run_named_cases("capi_async_task_step", tests, sizeof tests / sizeof tests[0], argc, argv);
}
