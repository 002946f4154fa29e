// SPDX-License-Identifier: MIT
/* Worlds on threads (issue 9, item 5).
 *
 * 1. Several worlds stepped on several threads at once give bitwise the particles they give
 *    when the same worlds are stepped one after another on one thread (one shared context,
 *    and one context per thread). A step is deterministic on one backend, so any difference
 *    is state shared between worlds that should not be.
 * 2. A world used from two threads at once: every call that checks the world lock returns
 *    SPH_OK or SPH_ERROR_WORLD_LOCKED (never anything else), a locked call changes nothing,
 *    the lock is observed, and the world ends bitwise where an undisturbed copy ends.
 *
 * 3. The worker count changes no bit: a dam break of about 9,000 particles (above the CPU backend's
 *    one-thread limit of 4,096) with surface tension, the normalised density and the walls'
 *    density share ends bitwise alike on 1, 2 and 3 workers. Every particle's result depends
 *    on its index alone and the reductions are max/min, so neither the split of the loops
 *    (dynamic chunks, handed out in whatever order the threads come) nor their count may
 *    change a result. The same for DFSPH (with surface tension, Clavet's viscosity and the walls'
 *    density share): its solves' mean errors are summed in storage order, so the iteration
 *    counts, and with them every result, may not depend on the workers either.
 *
 * Run under ThreadSanitizer in scripts/test (build-tsan/), where any data race fails the run.
 * Worker threads never call cmocka (its failure path longjmps); they record results and the
 * main thread checks them. */
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

/* kFrames: under ThreadSanitizer two frames (each of them tens of substeps, every pass of the
 * step's run concurrently in the four worlds; five took 47 s of CI's TSan stage, which waits on
 * this test alone, against 9 s in Release). */
#ifdef SPH_TEST_TSAN_BUILD
enum { kWorldCount = 4, kFrames = 2, kCapacity = 3000 };
#else
enum { kWorldCount = 4, kFrames = 5, kCapacity = 3000 };
#endif
static const float kFrameDt = 1.0f / 60.0f;

typedef struct particle_dump {
  uint32_t count;
  float positions[3 * kCapacity];
  float velocities[3 * kCapacity];
  uint32_t ids[kCapacity];
} particle_dump;

/* A small dam break in a tank, different per variant so no two worlds do the same work. The
 * tank's SDF asset is released right away (the collider keeps it). */
static sph_result build_world(sph_context* context, int variant, sph_world** out) {
  const support_tank tank = {{0.0f, 0.0f, 0.0f}, {0.3f, 0.3f, 0.15f}, 0.02f, 0.0f};
  sph_world_def def;
  sph_world_params params;
  sph_vec3 column_min, column_max;
  sph_world* world = NULL;
  sph_result r;

  sph_world_def_init(&def);
  def.capacity = kCapacity;
  def.particle_spacing = 0.02f;
  if ((r = sph_world_create(context, &def, &world)) != SPH_OK) return r;
  sph_world_params_init(&params);
  params.max_substeps = 200;
  params.gravity.x = 0.5f * (float)variant; /* a different slosh per variant */
  if ((r = sph_world_set_params(world, &params)) != SPH_OK) goto fail;

  column_min.x = -0.28f;
  column_min.y = -0.28f;
  column_min.z = -0.13f;
  column_max.x = -0.28f + 0.16f + 0.02f * (float)variant;
  column_max.y = 0.05f;
  column_max.z = 0.13f;
  r = support_dam_break(context, world, &tank, column_min, column_max, NULL, NULL, NULL);
  if (r != SPH_OK) goto fail;
  *out = world;
  return SPH_OK;
fail:
  sph_world_destroy(world);
  return r;
}

static sph_result dump_particles(const sph_world* world, particle_dump* out) {
  sph_result r;
  memset(out, 0, sizeof *out);
  if ((r = sph_world_get_particle_count(world, &out->count)) != SPH_OK) return r;
  if ((r = sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, out->positions, sizeof out->positions, 0,
                                    0, out->count, NULL)) != SPH_OK)
    return r;
  if ((r = sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, out->velocities, sizeof out->velocities, 0,
                                    0, out->count, NULL)) != SPH_OK)
    return r;
  return sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, out->ids, sizeof out->ids, 0, 0, out->count, NULL);
}

static int dumps_equal(const particle_dump* a, const particle_dump* b) {
  return a->count == b->count && memcmp(a->positions, b->positions, sizeof(float) * 3 * a->count) == 0 &&
         memcmp(a->velocities, b->velocities, sizeof(float) * 3 * a->count) == 0 &&
         memcmp(a->ids, b->ids, sizeof(uint32_t) * a->count) == 0;
}

/* Contexts for the CPU backend get two workers each: several worlds with OpenMP inside each is
 * the case to prove. Under ThreadSanitizer one worker: libgomp is not instrumented, so its
 * barriers would be reported as races (the library's own threads are std/pthreads). */
static sph_result create_context(sph_context** out) {
  sph_context_def def;
  sph_result r = sph_test_context_def_init(&def);
  if (r != SPH_OK) return r;
#ifdef SPH_TEST_TSAN_BUILD
  def.cpu_worker_count = 1;
#else
  def.cpu_worker_count = 2;
#endif
  return sph_context_create(&def, out);
}

/* ---- 1. independent worlds on independent threads ------------------------------------------ */
typedef struct world_job {
  sph_context* shared_context; /* NULL: the job makes (and destroys) its own context */
  int variant;
  sph_result result;
  char error[256];
  particle_dump* dump;
} world_job;

static void run_job(world_job* job) {
  sph_context* context = job->shared_context;
  sph_world* world = NULL;
  sph_result r = SPH_OK;
  if (!context) r = create_context(&context);
  if (r == SPH_OK) r = build_world(context, job->variant, &world);
  for (int frame = 0; r == SPH_OK && frame < kFrames; ++frame) r = sph_world_step(world, kFrameDt);
  if (r == SPH_OK) r = dump_particles(world, job->dump);
  if (r != SPH_OK) snprintf(job->error, sizeof job->error, "%s", sph_get_last_error());
  sph_world_destroy(world);
  if (!job->shared_context) sph_context_destroy(context);
  job->result = r;
}

static void* job_thread(void* arg) {
  run_job((world_job*)arg);
  return NULL;
}

static particle_dump serial_dumps[kWorldCount];
static particle_dump threaded_dumps[kWorldCount];

static void check_threaded_worlds(int shared_context) {
  sph_context* context = NULL;
  world_job serial[kWorldCount], threaded[kWorldCount];
  pthread_t threads[kWorldCount];
  EXPECT_OK(create_context(&context));
  for (int i = 0; i < kWorldCount; ++i) {
    serial[i] = (world_job){context, i, SPH_OK, "", &serial_dumps[i]};
    run_job(&serial[i]);
    if (serial[i].result != SPH_OK) fail_msg("serial world %d: %s", i, serial[i].error);
    assert_true(serial_dumps[i].count > 500u); /* the fill produced a real load */
  }
  for (int i = 0; i < kWorldCount; ++i) {
    threaded[i] = (world_job){shared_context ? context : NULL, i, SPH_OK, "", &threaded_dumps[i]};
    assert_int_equal(pthread_create(&threads[i], NULL, job_thread, &threaded[i]), 0);
  }
  for (int i = 0; i < kWorldCount; ++i) assert_int_equal(pthread_join(threads[i], NULL), 0);
  for (int i = 0; i < kWorldCount; ++i) {
    if (threaded[i].result != SPH_OK) fail_msg("threaded world %d: %s", i, threaded[i].error);
    if (!dumps_equal(&serial_dumps[i], &threaded_dumps[i]))
      fail_msg("world %d stepped on its own thread differs from the same world stepped alone", i);
  }
  /* The variants differ from each other, so equality above is not a coincidence of one state. */
  assert_false(dumps_equal(&serial_dumps[0], &serial_dumps[1]));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_worlds_on_threads_shared_context(void** state) {
  (void)state;
  check_threaded_worlds(1);
}

static void test_worlds_on_threads_own_contexts(void** state) {
  (void)state;
  check_threaded_worlds(0);
}

/* ---- 2. one world, two threads ----------------------------------------------------------------- */
typedef struct intruder {
  sph_world* world;
  sph_world_params params; /* what set_params writes: the values the world already has */
  int stop;                /* guarded by mutex */
  long rounds;             /* loop rounds begun, guarded by mutex */
  pthread_mutex_t mutex;
  long ok_calls;
  long locked_calls;
  long other_results;
  sph_result first_other;
  char first_other_message[256];
  long locked_without_message;
} intruder;

static int intruder_should_stop(intruder* in) {
  int stop;
  pthread_mutex_lock(&in->mutex);
  stop = in->stop;
  if (!stop) ++in->rounds;
  pthread_mutex_unlock(&in->mutex);
  return stop;
}

static long intruder_rounds(intruder* in) {
  long rounds;
  pthread_mutex_lock(&in->mutex);
  rounds = in->rounds;
  pthread_mutex_unlock(&in->mutex);
  return rounds;
}

/* Waits until the intruder has begun `rounds` loop rounds. */
static void wait_for_rounds(intruder* in, long rounds) {
  while (intruder_rounds(in) < rounds) sched_yield();
}

static void intruder_record(intruder* in, sph_result r) {
  if (r == SPH_OK) {
    ++in->ok_calls;
  } else if (r == SPH_ERROR_WORLD_LOCKED) {
    ++in->locked_calls;
    if (strstr(sph_get_last_error(), "in use") == NULL) ++in->locked_without_message;
  } else if (in->other_results++ == 0) {
    in->first_other = r;
    snprintf(in->first_other_message, sizeof in->first_other_message, "%s", sph_get_last_error());
  }
}

/* Calls that take the world lock, none of which changes the simulation's outcome. */
static void* intruder_thread(void* arg) {
  intruder* in = (intruder*)arg;
  static float scratch[3 * kCapacity];
  while (!intruder_should_stop(in)) {
    sph_stats stats;
    sph_stats_init(&stats);
    intruder_record(in, sph_world_get_stats(in->world, &stats));
    intruder_record(in, sph_world_set_params(in->world, &in->params));
    intruder_record(in, sph_world_copy_attribute(in->world, SPH_ATTRIBUTE_POSITION, scratch, sizeof scratch,
                                                 0, 0, kCapacity, NULL));
  }
  return NULL;
}

static void test_world_used_from_two_threads(void** state) {
  sph_context* context = NULL;
  sph_world *world = NULL, *reference = NULL;
  static particle_dump reference_dump, world_dump;
  intruder in;
  pthread_t thread;
  long owner_locked = 0;
  (void)state;

  EXPECT_OK(create_context(&context));
  EXPECT_OK(build_world(context, 1, &world));
  EXPECT_OK(build_world(context, 1, &reference));
  memset(&in, 0, sizeof in);
  in.world = world;
  sph_world_params_init(&in.params);
  EXPECT_OK(sph_world_get_params(world, &in.params));
  assert_int_equal(pthread_mutex_init(&in.mutex, NULL), 0);
  assert_int_equal(pthread_create(&thread, NULL, intruder_thread, &in), 0);
  /* The intruder is running before the owner's first step (a GPU frame can be over before a
   * new thread is scheduled). */
  wait_for_rounds(&in, 1);

  /* The owner steps kFrames frames; a step that finds the intruder inside the world gets
   * WORLD_LOCKED, did nothing, and is retried. */
  for (int frame = 0; frame < kFrames;) {
    const sph_result r = sph_world_step(world, kFrameDt);
    if (r == SPH_OK) {
      ++frame;
    } else if (r == SPH_ERROR_WORLD_LOCKED) {
      ++owner_locked;
    } else {
      fail_msg("owner's step: %s (%s)", sph_result_string(r), sph_get_last_error());
    }
  }
  /* Two more rounds with the world free: the second runs wholly after the owner's last step,
   * so its calls must succeed (on the GPU the owner can hold the world for every round the
   * intruder made during the frames). */
  wait_for_rounds(&in, intruder_rounds(&in) + 2);
  pthread_mutex_lock(&in.mutex);
  in.stop = 1;
  pthread_mutex_unlock(&in.mutex);
  assert_int_equal(pthread_join(thread, NULL), 0);
  pthread_mutex_destroy(&in.mutex);

  print_message("intruder: %ld calls ok, %ld WORLD_LOCKED; owner: %ld steps WORLD_LOCKED\n", in.ok_calls,
                in.locked_calls, owner_locked);
  if (in.other_results != 0)
    fail_msg("%ld intruder calls returned neither OK nor WORLD_LOCKED; first: %s (%s)", in.other_results,
             sph_result_string(in.first_other), in.first_other_message);
  assert_int_equal(in.locked_without_message, 0);
  /* kFrames frames of a 3,000-particle tank take tens of milliseconds; the intruder's calls are
   * microseconds: it must have run into the owner's steps. */
  assert_true(in.locked_calls + owner_locked > 0);
  assert_true(in.ok_calls > 0);

  for (int frame = 0; frame < kFrames; ++frame) EXPECT_OK(sph_world_step(reference, kFrameDt));
  EXPECT_OK(dump_particles(world, &world_dump));
  EXPECT_OK(dump_particles(reference, &reference_dump));
  if (!dumps_equal(&world_dump, &reference_dump))
    fail_msg("the world used from two threads ended differently from an undisturbed copy");
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_world_destroy(reference));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- 3. the worker count changes no bit ----------------------------------------------------- */
typedef struct worker_run {
  float* positions;
  float* velocities;
  uint32_t count;
} worker_run;

static sph_result run_with_workers(unsigned workers, sph_solver solver, worker_run* out) {
  const support_tank tank = {{0.0f, 0.0f, 0.0f}, {0.3f, 0.3f, 0.15f}, 0.02f, 0.0f};
  const sph_vec3 column_min = {-0.28f, -0.28f, -0.13f}, column_max = {-0.08f, 0.08f, 0.13f};
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world_def def;
  sph_world_params params;
  sph_world* world = NULL;
  uint32_t count = 0;
  sph_result r = sph_test_context_def_init(&context_def);
  if (r != SPH_OK) return r;
  context_def.cpu_worker_count = workers;
  if ((r = sph_context_create(&context_def, &context)) != SPH_OK) return r;
  sph_world_def_init(&def);
  def.capacity = 12000;
  def.particle_spacing = 0.014f;
  def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_BOUNDARY_DENSITY;
  if (solver == SPH_SOLVER_DFSPH) { /* DFSPH refuses the normalised density */
    def.solver = SPH_SOLVER_DFSPH;
    def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_BOUNDARY_DENSITY;
    def.viscosity_method = SPH_VISCOSITY_CLAVET;
  }
  if ((r = sph_world_create(context, &def, &world)) != SPH_OK) goto done;
  sph_world_params_init(&params);
  params.max_substeps = 200;
  if ((r = sph_world_set_params(world, &params)) != SPH_OK) goto done;
  if ((r = support_dam_break(context, world, &tank, column_min, column_max, NULL, NULL, &count)) != SPH_OK)
    goto done;
  if (count <= 4096u) {
    fail_msg("the dam break has %u particles: the CPU backend would run it on one thread", count);
  }
  for (int frame = 0; r == SPH_OK && frame < 3; ++frame) r = sph_world_step(world, kFrameDt);
  if (r == SPH_OK) r = support_copy(world, SPH_ATTRIBUTE_POSITION, (void**)&out->positions, &out->count);
  if (r == SPH_OK) r = support_copy(world, SPH_ATTRIBUTE_VELOCITY, (void**)&out->velocities, &out->count);
done:
  if (r != SPH_OK) print_error("run_with_workers: %s\n", sph_get_last_error());
  sph_world_destroy(world);
  sph_context_destroy(context);
  return r;
}

static void check_worker_count_changes_no_bit(sph_solver solver) {
#ifdef SPH_TEST_TSAN_BUILD
  skip(); /* one worker under ThreadSanitizer (create_context) */
#endif
  if (sph_test_backend() == SPH_BACKEND_CUDA) skip(); /* the CPU backend's workers */
  worker_run runs[3] = {{0}};
  for (unsigned w = 0; w < 3; ++w) EXPECT_OK(run_with_workers(w + 1u, solver, &runs[w]));
  for (unsigned w = 1; w < 3; ++w) {
    assert_int_equal(runs[w].count, runs[0].count);
    const size_t bytes = sizeof(float) * 3u * runs[0].count;
    if (memcmp(runs[w].positions, runs[0].positions, bytes) != 0 ||
        memcmp(runs[w].velocities, runs[0].velocities, bytes) != 0)
      fail_msg("%u workers ended differently from one worker", w + 1u);
  }
  for (unsigned w = 0; w < 3; ++w) {
    free(runs[w].positions);
    free(runs[w].velocities);
  }
}

static void test_worker_count_changes_no_bit(void** state) {
  (void)state;
  check_worker_count_changes_no_bit(SPH_SOLVER_WCSPH);
}

static void test_dfsph_worker_count_changes_no_bit(void** state) {
  (void)state;
  check_worker_count_changes_no_bit(SPH_SOLVER_DFSPH);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_worlds_on_threads_shared_context),
      cmocka_unit_test(test_worlds_on_threads_own_contexts),
      cmocka_unit_test(test_world_used_from_two_threads),
      cmocka_unit_test(test_worker_count_changes_no_bit),
      cmocka_unit_test(test_dfsph_worker_count_changes_no_bit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
