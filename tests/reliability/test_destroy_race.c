// SPDX-License-Identifier: MIT
/* Destroying an object while another thread's call uses it (issue 23, item 1).
 *
 * 1. sph_world_destroy racing sph_world_step, sph_world_copy_attribute, sph_world_get_stats and
 *    a const getter on the same world, thousands of times: each intruder's call answers OK,
 *    INCOMPLETE, WORLD_LOCKED (destroy holds the world) or INVALID_HANDLE (the world is gone);
 *    destroy answers OK or WORLD_LOCKED (a call holds it) and is retried until OK. Before the
 *    fix destroy checked the lock and then freed the world, so a call that entered between
 *    the two used freed memory (SIGSEGV in Release, heap-use-after-free under ASan).
 * 2. sph_context_destroy racing world creation on that context: BUSY or OK, and a creation
 *    that lost the race answers INVALID_HANDLE; no world is ever made on a freed context.
 * 3. sph_sdf_destroy racing sph_sdf_sample, sph_sdf_update and sph_collider_create with that
 *    asset: every call answers OK or its not-live error, and a collider made in the race keeps
 *    the asset alive.
 *
 * One round in kHeldEvery is held (destroy_race.h, handshake): the destroyer waits until an
 * intruder holds the object, so that "destroy met a call in flight" is checked in every run,
 * not left to the scheduler: a step begun and not yet collected (WORLD_LOCKED, then the step is
 * collected OK), a world alive on the context (BUSY), a collider made before the SDF handle
 * dies. The other rounds are free races: which interleavings they meet is printed, not asserted.
 *
 * Under ThreadSanitizer (scripts/test, build-tsan/) and ASan (build-sanitize/) any data race or
 * use after free fails the run, so most of this test's force is there; in Release it checks
 * the results. Part of the hostile-input suite (ctest label `hostile`). */
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#include "destroy_race.h"

/* Fewer rounds in the sanitizer builds (ThreadSanitizer's, and ASan + UBSan's, where each round costs
 * several times the Release build's: 49 s of the 2-core CI's sanitizer stage at the full counts). */
#if defined(SPH_TEST_TSAN_BUILD) || defined(SPH_TEST_ASAN_BUILD)
enum { kWorldRounds = 800, kContextRounds = 250, kSdfRounds = 800 };
#else
enum { kWorldRounds = 2000, kContextRounds = 500, kSdfRounds = 2000 };
#endif
enum { kIntruders = 4 };

/* ---- 1. world destroy against calls on the world -------------------------------------------- */
typedef struct world_intruder {
  sph_world* world;
  int kind;
  int* slow;        /* set (relaxed) by the destroyer when it keeps finding the world busy */
  handshake* hold;  /* a held round's stepping intruder: begins a step and posts */
  volatile int* go; /* guarded by go_mutex */
  pthread_mutex_t* go_mutex;
  tally seen;
  sph_result held_step; /* what sph_world_step_wait returned for the held step */
} world_intruder;

/* Until sph_world_step_wait collects it, a begun step holds the world (sph_c.h), running or
 * not: a destroy meanwhile must answer WORLD_LOCKED, on any backend. */
static void hold_world_in_a_step(world_intruder* in) {
  sph_result r;
  for (;;) {
    r = sph_world_step_begin(in->world, 1.0f / 600.0f);
    tally_add(&in->seen, r);
    if (r != SPH_ERROR_WORLD_LOCKED) break; /* another intruder's call is inside */
    pause_between_calls(in->slow);
  }
  handshake_post(in->hold, r);
  if (r != SPH_OK) return;
  handshake_wait_answer(in->hold);
  in->held_step = sph_world_step_wait(in->world);
  tally_add(&in->seen, in->held_step);
}

/* Calls into the world until it is gone (INVALID_HANDLE), then stops: the next round's world
 * may reuse the address, and a stale call must not reach it. */
static void* world_intruder_thread(void* arg) {
  world_intruder* in = (world_intruder*)arg;
  static __thread float scratch[3 * 64];
  wait_go(in->go_mutex, in->go);
  if (in->hold) hold_world_in_a_step(in);
  for (;;) {
    sph_result r;
    switch (in->kind) {
      case 0:
        r = sph_world_step(in->world, 1.0f / 600.0f);
        break;
      case 1:
        r = sph_world_copy_attribute(in->world, SPH_ATTRIBUTE_POSITION, scratch, sizeof scratch, 0, 0, 64,
                                     NULL);
        break;
      case 2: {
        sph_stats stats;
        sph_stats_init(&stats);
        r = sph_world_get_stats(in->world, &stats);
        break;
      }
      default: {
        uint32_t count = 0;
        r = sph_world_get_particle_count(in->world, &count);
        if (r == SPH_OK && count != kParticles) r = SPH_ERROR_INTERNAL; /* a torn or freed world */
        break;
      }
    }
    tally_add(&in->seen, r);
    if (r == SPH_ERROR_INVALID_HANDLE) return NULL;
    pause_between_calls(in->slow);
  }
}

/* One destroy, tallied; nonzero once it answered anything but WORLD_LOCKED (OK, or what the
 * tally counts as "other"). */
static int try_destroy_world(sph_world* world, tally* destroys) {
  const sph_result r = sph_world_destroy(world);
  tally_add(destroys, r);
  return r != SPH_ERROR_WORLD_LOCKED;
}

static void test_world_destroy_races_calls(void** state) {
  sph_context* context = create_context();
  tally intruders = {0}, destroys = {0};
  long free_rounds_locked = 0, free_rounds_with_call = 0, held_refused = 0, held_collected = 0;
  (void)state;
  for (int round = 0; round < kWorldRounds; ++round) {
    world_intruder in[kIntruders];
    pthread_t threads[kIntruders];
    pthread_mutex_t go_mutex;
    handshake hold = {SPH_OK, 0, 0};
    volatile int go = 0;
    int slow = 0, gone = 0;
    const int held = held_round(round);
    long locked_before = destroys.locked, ok_before = intruders.ok;
    sph_world* world = create_world(context);
    if (!world) fail_msg("round %d: creating the world: %s", round, sph_get_last_error());
    assert_int_equal(pthread_mutex_init(&go_mutex, NULL), 0);
    for (int i = 0; i < kIntruders; ++i) {
      memset(&in[i], 0, sizeof in[i]);
      in[i].world = world;
      in[i].kind = (i + round) % kIntruders;
      in[i].slow = &slow;
      in[i].hold = held && in[i].kind == 0 ? &hold : NULL;
      in[i].held_step = SPH_OK;
      in[i].go = &go;
      in[i].go_mutex = &go_mutex;
      assert_int_equal(pthread_create(&threads[i], NULL, world_intruder_thread, &in[i]), 0);
    }
    pthread_mutex_lock(&go_mutex);
    go = 1;
    pthread_mutex_unlock(&go_mutex);
    if (held) {
      const sph_result begun = handshake_wait_post(&hold);
      gone = try_destroy_world(world, &destroys);
      if (begun == SPH_OK && destroys.locked > locked_before) ++held_refused;
      handshake_answer(&hold);
    } else {
      /* A varying head start, so destroy meets the intruders at every point of their calls. */
      for (int spin = 0; spin < round % 7; ++spin) sched_yield();
    }
    while (!gone) {
      gone = try_destroy_world(world, &destroys);
      if (destroys.locked - locked_before == 100) __atomic_store_n(&slow, 1, __ATOMIC_RELAXED);
      if (!gone) sched_yield();
    }
    for (int i = 0; i < kIntruders; ++i) {
      assert_int_equal(pthread_join(threads[i], NULL), 0);
      tally_merge(&intruders, &in[i].seen);
      if (in[i].hold && in[i].held_step == SPH_OK) ++held_collected;
    }
    pthread_mutex_destroy(&go_mutex);
    if (!held && destroys.locked > locked_before) ++free_rounds_locked;
    if (!held && intruders.ok > ok_before) ++free_rounds_with_call;
    expect_no_other("destroy", &destroys);
  }
  print_message(
      "world: %d rounds (%ld held: destroy refused %ld times, the step collected OK %ld times); free "
      "rounds: destroy found a call inside in %ld, calls got in first in %ld; in all: destroy %ld "
      "WORLD_LOCKED, intruders %ld ok, %ld WORLD_LOCKED, %ld INVALID_HANDLE\n",
      kWorldRounds, held_rounds(kWorldRounds), held_refused, held_collected, free_rounds_locked,
      free_rounds_with_call, destroys.locked, intruders.ok, intruders.locked, intruders.invalid);
  expect_no_other("intruders", &intruders);
  assert_int_equal(destroys.ok, kWorldRounds);
  /* Each intruder ends on INVALID_HANDLE, once per round. */
  assert_int_equal(intruders.invalid, (long)kWorldRounds * kIntruders);
  /* Every held round: destroy met the begun step and was refused, and the step, collected
   * afterwards, ran as if nothing had happened. */
  assert_int_equal(held_refused, held_rounds(kWorldRounds));
  assert_int_equal(held_collected, held_rounds(kWorldRounds));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- 2. context destroy against world creation on it ---------------------------------------- */
typedef struct context_intruder {
  sph_context* context;
  int* slow;
  int started;     /* set just before the first sph_world_create */
  handshake* hold; /* a held round: posts with its first world alive, destroys it once answered */
  volatile int* go;
  pthread_mutex_t* go_mutex;
  tally creates, destroys;
} context_intruder;

static void* context_intruder_thread(void* arg) {
  context_intruder* in = (context_intruder*)arg;
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 16;
  wait_go(in->go_mutex, in->go);
  __atomic_store_n(&in->started, 1, __ATOMIC_RELEASE);
  for (;;) {
    sph_world* world = NULL;
    const sph_result r = sph_world_create(in->context, &def, &world);
    tally_add(&in->creates, r);
    if (in->hold) {
      handshake_post(in->hold, r);
      if (r == SPH_OK) handshake_wait_answer(in->hold);
      in->hold = NULL;
    }
    if (r != SPH_OK) return NULL;
    if (in->creates.ok % 2 == 0) sched_yield(); /* a world alive meanwhile: destroy must say BUSY */
    tally_add(&in->destroys, sph_world_destroy(world));
    /* Back to back at first (a yield here leaves the context free most of the time), then
     * slowed, so a starved destroyer gets its turn. */
    if (in->creates.ok > 64 || __atomic_load_n(in->slow, __ATOMIC_RELAXED)) {
      struct timespec pause = {0, 100000};
      nanosleep(&pause, NULL);
    }
  }
}

static void test_context_destroy_races_world_create(void** state) {
  tally creates = {0}, world_destroys = {0}, context_destroys = {0};
  long held_busy = 0;
  (void)state;
  for (int round = 0; round < kContextRounds; ++round) {
    context_intruder in;
    pthread_t thread;
    pthread_mutex_t go_mutex;
    handshake hold = {SPH_OK, 0, 0};
    volatile int go = 0;
    int slow = 0;
    sph_result r = SPH_ERROR_BUSY;
    long busy_before = context_destroys.busy;
    sph_context* context = create_context();
    assert_int_equal(pthread_mutex_init(&go_mutex, NULL), 0);
    memset(&in, 0, sizeof in);
    in.context = context;
    in.slow = &slow;
    in.hold = held_round(round) ? &hold : NULL;
    in.go = &go;
    in.go_mutex = &go_mutex;
    assert_int_equal(pthread_create(&thread, NULL, context_intruder_thread, &in), 0);
    pthread_mutex_lock(&go_mutex);
    go = 1;
    pthread_mutex_unlock(&go_mutex);
    if (held_round(round)) {
      const sph_result created = handshake_wait_post(&hold);
      r = sph_context_destroy(context);
      tally_add(&context_destroys, r);
      if (created == SPH_OK && r == SPH_ERROR_BUSY) ++held_busy;
      handshake_answer(&hold);
    } else {
      /* Wait until the creator is about to create: where thread start-up is slower than a few
       * yields (CUDA's context), the destroyer otherwise always came first and the race was
       * never run (0 BUSY, 0 worlds in 500 rounds on an H200 host). */
      while (!__atomic_load_n(&in.started, __ATOMIC_ACQUIRE)) sched_yield();
      for (int spin = 0; spin < round % 5; ++spin) sched_yield();
    }
    while (r == SPH_ERROR_BUSY) {
      r = sph_context_destroy(context);
      tally_add(&context_destroys, r);
      if (r != SPH_ERROR_BUSY) break;
      if (context_destroys.busy - busy_before == 10) __atomic_store_n(&slow, 1, __ATOMIC_RELAXED);
      sched_yield();
    }
    assert_int_equal(pthread_join(thread, NULL), 0);
    pthread_mutex_destroy(&go_mutex);
    tally_merge(&creates, &in.creates);
    tally_merge(&world_destroys, &in.destroys);
  }
  print_message(
      "context: %d rounds (%ld held: BUSY %ld times); context destroy: %ld BUSY; world create: %ld ok, %ld "
      "INVALID_HANDLE\n",
      kContextRounds, held_rounds(kContextRounds), held_busy, context_destroys.busy, creates.ok,
      creates.invalid);
  expect_no_other("context destroy", &context_destroys);
  expect_no_other("world create", &creates);
  expect_no_other("world destroy", &world_destroys);
  assert_int_equal(context_destroys.ok, kContextRounds);
  assert_int_equal(creates.invalid, kContextRounds); /* the creator stops on its first failure */
  assert_int_equal(world_destroys.ok, creates.ok);   /* every world made was destroyed */
  /* Every held round: destroy met a world alive on the context. */
  assert_int_equal(held_busy, held_rounds(kContextRounds));
}

/* ---- 3. SDF destroy against calls that use the asset ------------------------------------------ */
typedef struct sdf_intruder {
  sph_sdf* sdf;
  sph_world* world; /* kind 2 makes colliders on it */
  int kind;
  handshake* hold; /* a held round's collider maker: posts after its first collider */
  volatile int* go;
  pthread_mutex_t* go_mutex;
  tally seen;
  long colliders;
} sdf_intruder;

/* Kinds: 0 samples, 1 reads the dimensions, 2 makes colliders with the asset (at most 32 a
 * round, then reads the dimensions), 3 updates a voxel. An update is never raced against
 * readers of the same voxels (sph_sdf_update's contract), only against destroy. */
static void* sdf_intruder_thread(void* arg) {
  sdf_intruder* in = (sdf_intruder*)arg;
  wait_go(in->go_mutex, in->go);
  for (;;) {
    sph_result r;
    if (in->kind == 0) {
      float distance = 0.0f;
      const sph_vec3 p = {0.0f, 0.0f, 0.0f};
      r = sph_sdf_sample(in->sdf, p, &distance);
      if (r == SPH_OK && !(distance < 0.0f)) r = SPH_ERROR_INTERNAL; /* the centre is inside */
    } else if (in->kind == 3) {
      const uint32_t origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
      const float far_outside = 1.0f; /* a corner voxel: stays outside */
      r = sph_sdf_update(in->sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, &far_outside, SPH_MEMORY_HOST);
    } else if (in->kind == 2 && in->colliders < 32) {
      sph_collider_def def;
      sph_collider_id id;
      sph_collider_def_init(&def);
      def.sdf = in->sdf;
      r = sph_collider_create(in->world, &def, &id);
      if (r == SPH_OK) ++in->colliders;
      if (in->hold) {
        handshake_post(in->hold, r);
        in->hold = NULL;
      }
    } else {
      uint32_t dims[3] = {0, 0, 0};
      r = sph_sdf_get_dims(in->sdf, dims);
      if (r == SPH_OK && (dims[0] == 0 || dims[0] != dims[1] || dims[1] != dims[2])) r = SPH_ERROR_INTERNAL;
    }
    tally_add(&in->seen, r);
    if (r == SPH_ERROR_INVALID_HANDLE) return NULL;
    pause_between_calls(NULL);
  }
}

static void test_sdf_destroy_races_users(void** state) {
  sph_context* context = create_context();
  sph_world* world = create_world(context);
  tally seen = {0};
  long colliders = 0, users_started = 0, held_colliders = 0;
  sph_shape_desc shape;
  (void)state;
  assert_non_null(world);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  shape.voxel_size = 0.02f;
  for (int round = 0; round < kSdfRounds; ++round) {
    static const int kinds[2][3] = {{0, 1, 2}, {3, 1, -1}};
    const int* round_kinds = kinds[round % 2];
    const int users = round % 2 == 0 ? 3 : 2;
    sdf_intruder in[3];
    pthread_t threads[3];
    pthread_mutex_t go_mutex;
    handshake hold = {SPH_OK, 0, 0};
    volatile int go = 0;
    sph_sdf* sdf = NULL;
    EXPECT_OK(sph_sdf_create_shape(context, &shape, &sdf));
    assert_int_equal(pthread_mutex_init(&go_mutex, NULL), 0);
    for (int i = 0; i < users; ++i) {
      memset(&in[i], 0, sizeof in[i]);
      in[i].sdf = sdf;
      in[i].world = world;
      in[i].kind = round_kinds[i];
      in[i].hold = held_round(round) && round_kinds[i] == 2 ? &hold : NULL;
      in[i].go = &go;
      in[i].go_mutex = &go_mutex;
      assert_int_equal(pthread_create(&threads[i], NULL, sdf_intruder_thread, &in[i]), 0);
      ++users_started;
    }
    pthread_mutex_lock(&go_mutex);
    go = 1;
    pthread_mutex_unlock(&go_mutex);
    if (held_round(round)) {
      if (handshake_wait_post(&hold) == SPH_OK) ++held_colliders;
    } else {
      for (int spin = 0; spin < round % 7; ++spin) sched_yield();
    }
    EXPECT_OK(sph_sdf_destroy(sdf));
    for (int i = 0; i < users; ++i) {
      assert_int_equal(pthread_join(threads[i], NULL), 0);
      tally_merge(&seen, &in[i].seen);
      colliders += in[i].colliders;
    }
    pthread_mutex_destroy(&go_mutex);
    /* Colliders outlive the handle; keep the world small. */
    if (round % 64 == 63) {
      EXPECT_OK(sph_world_destroy(world));
      world = create_world(context);
      assert_non_null(world);
    }
  }
  print_message(
      "sdf: %d rounds (%ld held: a collider made first %ld times); users: %ld ok (%ld colliders), %ld "
      "INVALID_HANDLE; world locked %ld\n",
      kSdfRounds, held_rounds(kSdfRounds), held_colliders, seen.ok, colliders, seen.invalid, seen.locked);
  expect_no_other("sdf users", &seen);
  assert_int_equal(seen.invalid, users_started); /* each user ends on INVALID_HANDLE */
  assert_int_equal(held_colliders, held_rounds(kSdfRounds));
  EXPECT_OK(sph_world_step(world, 1.0f / 600.0f)); /* colliders whose handle died still work */
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_world_destroy_races_calls),
      cmocka_unit_test(test_context_destroy_races_world_create),
      cmocka_unit_test(test_sdf_destroy_races_users),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
