// SPDX-License-Identifier: MIT
/* Asynchronous steps (issue 21, item 1): sph_world_step_begin / _wait / _poll.
 *
 * 1. A frame begun and waited for ends bitwise where sph_world_step ends it (same world, same
 *    backend: a step is deterministic), three frames in a row, waited from another thread once.
 * 2. While a step is pending, every other call on the world answers WORLD_LOCKED and changes
 *    nothing (destroy included); poll answers and turns to done; cancel reaches the step.
 * 3. A step that fails (particles piled into one cell: SPH_ERROR_CAPACITY) reports its error and
 *    message through wait on the waiting thread, and the world is as before the begin.
 * 4. Misuse: wait or poll without a begin, a second wait, a second begin, bad arguments, dead
 *    handles: each a clear error, nothing started.
 * 5. sph_cuda_world_step_begin_on_stream (the legacy default stream): on a CUDA world the frames
 *    end where sph_world_step ends them; on a CPU world UNSUPPORTED and nothing started. (The
 *    stream ordering itself is checked on the GPU: tests/gpu/check_stream_step.cu.)
 * Runs in the TSan stage (label threads) with one worker: libgomp is not instrumented. */
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "capi_async.h"
#include "sph_cuda.h"

static const float kFrameDt = 1.0f / 60.0f;

static sph_context* make_context(void) {
  sph_context_def def;
  sph_context* context = NULL;
  EXPECT_OK(sph_test_context_def_init(&def));
#ifdef SPH_TEST_TSAN_BUILD
  def.cpu_worker_count = 1;
#endif
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

/* A block of fluid falling in a box: about 1,000 particles, a few substeps a frame. */
static sph_world* make_world(sph_context* context) {
  uint32_t added = 0;
  sph_world* world = capi_falling_block(context, 4096, 0.2f, &added);
  assert_true(added > 500);
  return world;
}

typedef struct waiter {
  sph_world* world;
  sph_result result;
  char error[256];
} waiter;

static void* wait_on_thread(void* arg) {
  waiter* w = (waiter*)arg;
  w->result = sph_world_step_wait(w->world);
  snprintf(w->error, sizeof w->error, "%s", sph_get_last_error());
  return NULL;
}

static void test_same_frames_as_step(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_world* reference = capi_world_copy(context, world);
  waiter w;
  pthread_t thread;
  int frame;
  (void)state;
  for (frame = 0; frame < 3; ++frame) {
    EXPECT_OK(sph_world_step(reference, kFrameDt));
    EXPECT_OK(sph_world_step_begin(world, kFrameDt));
    if (frame == 1) {
      /* Collected by another thread than the one that began it. */
      w.world = world;
      w.result = SPH_ERROR_INTERNAL;
      assert_int_equal(pthread_create(&thread, NULL, wait_on_thread, &w), 0);
      assert_int_equal(pthread_join(thread, NULL), 0);
      assert_int_equal(w.result, SPH_OK);
      assert_string_equal(w.error, "");
    } else {
      EXPECT_OK(sph_world_step_wait(world));
    }
    capi_expect_same_particles(world, reference);
  }
  {
    sph_stats a, b;
    sph_stats_init(&a);
    sph_stats_init(&b);
    EXPECT_OK(sph_world_get_stats(world, &a));
    EXPECT_OK(sph_world_get_stats(reference, &b));
    assert_int_equal(a.substeps, b.substeps);
    assert_true(a.substeps > 0);
    assert_true(a.simulated_time == b.simulated_time);
  }
  EXPECT_OK(sph_world_destroy(reference));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_pending_step_holds_the_world(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_world_params params;
  sph_stats stats;
  uint32_t count = 0;
  float position[3];
  sph_bool32 done = 2;
  (void)state;
  capi_begin_long_frame_and_expect_held(context, world);
  sph_world_params_init(&params);
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_get_params(world, &params));
  sph_stats_init(&stats);
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_get_stats(world, &stats));
  EXPECT_ERROR(
      SPH_ERROR_WORLD_LOCKED, "world",
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, position, sizeof position, 0, 0, 1, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_done", sph_world_step_poll(world, NULL));
  EXPECT_OK(sph_world_step_poll(world, &done));
  assert_true(done == 0 || done == 1);

  /* 5,001 substeps of about 1e-4 s: the cancel stops the frame early (or waits for the next step). */
  capi_expect_cancelled_frame(world, "cancelled asynchronous frame");
  /* Free again. */
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  assert_true(count > 500);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_failed_step_reports_through_wait(void** state) {
  sph_context* context = make_context();
  (void)state;
  capi_expect_failed_step_reported(context);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_begin_on_stream(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_world* reference = capi_world_copy(context, world);
  int frame;
  (void)state;
  if (sph_test_backend() == SPH_BACKEND_CPU) {
    EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "CUDA", sph_cuda_world_step_begin_on_stream(world, kFrameDt, NULL));
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "no step was begun", sph_world_step_wait(world));
  } else {
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt",
                 sph_cuda_world_step_begin_on_stream(world, 0.0f, NULL));
    for (frame = 0; frame < 3; ++frame) {
      EXPECT_OK(sph_world_step(reference, kFrameDt));
      EXPECT_OK(sph_cuda_world_step_begin_on_stream(world, kFrameDt, NULL));
      EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world",
                   sph_cuda_world_step_begin_on_stream(world, kFrameDt, NULL));
      EXPECT_OK(sph_world_step_wait(world));
      capi_expect_same_particles(world, reference);
    }
  }
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_cuda_world_step_begin_on_stream(NULL, kFrameDt, NULL));
  EXPECT_OK(sph_world_destroy(reference));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_misuse(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_world* dead = make_world(context);
  sph_bool32 done = 7;
  (void)state;
  EXPECT_OK(sph_world_destroy(dead));

  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "no step was begun", sph_world_step_wait(world));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "no step was begun", sph_world_step_poll(world, &done));
  assert_int_equal(done, 7);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step_begin(world, 0.0f));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step_begin(world, -1.0f));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step_begin(world, capi_non_finite(0)));
  /* Nothing was started by the refused begins. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "no step was begun", sph_world_step_wait(world));

  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_begin(NULL, kFrameDt));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_wait(NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_poll(NULL, &done));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_begin(dead, kFrameDt));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_wait(dead));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step_poll(dead, &done));

  /* One wait per begin. */
  EXPECT_OK(sph_world_step_begin(world, kFrameDt));
  EXPECT_OK(sph_world_step_wait(world));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "already waited for", sph_world_step_wait(world));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_same_frames_as_step),
      cmocka_unit_test(test_pending_step_holds_the_world),
      cmocka_unit_test(test_failed_step_reports_through_wait),
      cmocka_unit_test(test_misuse),
      cmocka_unit_test(test_begin_on_stream),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
