// SPDX-License-Identifier: MIT
#include "capi_async.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int listed_threads(void) {
  int n = 0;
  struct dirent* e;
  DIR* d = opendir("/proc/self/task");
  assert_non_null(d);
  while ((e = readdir(d)) != NULL)
    if (e->d_name[0] != '.') ++n;
  closedir(d);
  return n;
}

/* The count once it holds still: a thread that pthread_join has returned for can still be listed
 * for a moment (the kernel wakes the joiner before it removes the thread), and on a loaded
 * machine a test's pool stopped just before was counted once as one thread more than it holds
 * (capi_async_task_step, session 43: 5 before, 4 after, the library having started none). Two
 * equal reads 20 ms apart, within 2 s. */
int capi_thread_count(void) {
  const struct timespec pause = {0, 20 * 1000 * 1000};
  int n = listed_threads();
  for (int k = 0; k < 100; ++k) {
    nanosleep(&pause, NULL);
    const int again = listed_threads();
    if (again == n) break;
    n = again;
  }
  return n;
}

sph_world* capi_falling_block(sph_context* context, uint32_t capacity, float side, uint32_t* added) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_fill_box_desc box;
  uint32_t count = 0;
  sph_world_def_init(&def);
  def.capacity = capacity;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = side;
  EXPECT_OK(sph_world_fill_box(world, &box, &count));
  if (added) *added = count;
  return world;
}

void capi_poll_until_done(const sph_world* world) {
  const struct timespec pause = {0, 1000000};
  sph_bool32 done = 0;
  int i;
  for (i = 0; i < 60000 && !done; ++i) {
    EXPECT_OK(sph_world_step_poll(world, &done));
    if (!done) nanosleep(&pause, NULL);
  }
  assert_int_equal(done, 1);
}

void capi_begin_long_frame_and_expect_held(sph_context* context, sph_world* world) {
  const float frame_dt = 1.0f / 60.0f;
  sph_world_params params;
  uint32_t count = 0;
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  params.dt_min = params.dt_max = 1e-4f;
  params.max_substeps = 10000;
  EXPECT_OK(sph_world_set_params(world, &params));

  EXPECT_OK(sph_world_step_begin(world, 0.5f));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_step(world, frame_dt));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_step_begin(world, frame_dt));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_get_particle_count(world, &count));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_set_params(world, &params));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_destroy(world));
  EXPECT_ERROR(SPH_ERROR_BUSY, "context", sph_context_destroy(context));
}

void capi_expect_cancelled_frame(sph_world* world, const char* what) {
  sph_stats stats;
  sph_result r;
  EXPECT_OK(sph_world_cancel_step(world));
  capi_poll_until_done(world);
  r = sph_world_step_wait(world);
  assert_true(r == SPH_INCOMPLETE || r == SPH_OK);
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  if (r == SPH_INCOMPLETE) {
    assert_true(stats.substeps < 5000);
    assert_true(stats.frame_time < 0.5f);
  } else {
    /* The whole frame: 0.5 s in steps of 1e-4f (a little under 1e-4), which leaves a last step a
     * little over 1e-4 that the clock splits in halves (landing_dt): 5,001 substeps. */
    assert_true(stats.frame_time == 0.5f);
    assert_int_equal(stats.substeps, 5001);
    assert_int_equal(sph_world_step(world, 1.0f / 60.0f), SPH_INCOMPLETE); /* uses up the cancel */
  }
  printf("%s: %s after %u substeps\n", what, sph_result_string(r), stats.substeps);
}

void capi_expect_failed_step_reported(sph_context* context) {
  const uint32_t n = 8000;
  sph_world_def def;
  sph_world* world = NULL;
  sph_world* before;
  sph_spawn_desc spawn;
  float* p;
  uint32_t i, first = 0;
  sph_world_def_init(&def);
  def.capacity = n;
  EXPECT_OK(sph_world_create(context, &def, &world));
  p = (float*)calloc(3u * n, sizeof(float));
  assert_non_null(p);
  for (i = 0; i < n; ++i) {
    p[3 * i] = 0.25f;
    p[3 * i + 1] = 0.5f;
    p[3 * i + 2] = 0.125f;
  }
  sph_spawn_desc_init(&spawn);
  spawn.count = n;
  spawn.positions = p;
  EXPECT_OK(sph_world_spawn(world, &spawn, &first));
  free(p);
  before = capi_world_copy(context, world);

  EXPECT_OK(sph_world_step_begin(world, 1.0f / 60.0f));
  assert_int_equal(sph_world_step_wait(world), SPH_ERROR_CAPACITY);
  assert_non_null(strstr(sph_get_last_error(), "particles share one cell"));
  capi_expect_same_particles(world, before);
  /* The failure was collected: the world is free and no step is pending. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "no step was begun", sph_world_step_wait(world));
  EXPECT_OK(sph_world_destroy(before));
  EXPECT_OK(sph_world_destroy(world));
}
