// SPDX-License-Identifier: MIT
#include "destroy_race.h"

#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

void tally_add(tally* t, sph_result r) {
  if (r == SPH_OK || r == SPH_INCOMPLETE) {
    ++t->ok;
  } else if (r == SPH_ERROR_WORLD_LOCKED) {
    ++t->locked;
  } else if (r == SPH_ERROR_INVALID_HANDLE) {
    ++t->invalid;
  } else if (r == SPH_ERROR_BUSY) {
    ++t->busy;
  } else if (t->other++ == 0) {
    t->first_other = r;
    snprintf(t->first_other_message, sizeof t->first_other_message, "%s", sph_get_last_error());
  }
}

void tally_merge(tally* into, const tally* t) {
  if (t->other != 0 && into->other == 0) {
    into->first_other = t->first_other;
    memcpy(into->first_other_message, t->first_other_message, sizeof into->first_other_message);
  }
  into->ok += t->ok;
  into->locked += t->locked;
  into->invalid += t->invalid;
  into->busy += t->busy;
  into->other += t->other;
}

void expect_no_other(const char* who, const tally* t) {
  if (t->other != 0)
    fail_msg("%s: %ld calls answered something else than expected; first: %s (%s)", who, t->other,
             sph_result_string(t->first_other), t->first_other_message);
}

sph_context* create_context(void) {
  sph_context_def def;
  sph_context* context = NULL;
  EXPECT_OK(sph_test_context_def_init(&def));
  def.cpu_worker_count = 1; /* the race is between API calls, not inside a step */
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

sph_world* create_world(sph_context* context) {
  sph_world_def def;
  sph_spawn_desc spawn;
  sph_world* world = NULL;
  float positions[3 * kParticles];
  sph_world_def_init(&def);
  def.capacity = 64;
  if (sph_world_create(context, &def, &world) != SPH_OK) return NULL;
  for (int i = 0; i < kParticles; ++i) {
    positions[3 * i + 0] = 0.02f * (float)(i % 2);
    positions[3 * i + 1] = 0.02f * (float)((i / 2) % 2);
    positions[3 * i + 2] = 0.02f * (float)(i / 4);
  }
  sph_spawn_desc_init(&spawn);
  spawn.count = kParticles;
  spawn.positions = positions;
  if (sph_world_spawn(world, &spawn, NULL) != SPH_OK) {
    sph_world_destroy(world);
    return NULL;
  }
  return world;
}

int wait_go(pthread_mutex_t* mutex, volatile int* go) {
  for (;;) {
    int v;
    pthread_mutex_lock(mutex);
    v = *go;
    pthread_mutex_unlock(mutex);
    if (v) return v;
    sched_yield();
  }
}

void pause_between_calls(const int* slow) {
  if (slow && __atomic_load_n(slow, __ATOMIC_RELAXED)) {
    struct timespec pause = {0, 100000};
    nanosleep(&pause, NULL);
  } else {
    sched_yield();
  }
}

void handshake_post(handshake* h, sph_result seen) {
  h->seen = seen;
  __atomic_store_n(&h->posted, 1, __ATOMIC_RELEASE);
}

sph_result handshake_wait_post(handshake* h) {
  while (!__atomic_load_n(&h->posted, __ATOMIC_ACQUIRE)) sched_yield();
  return h->seen;
}

void handshake_answer(handshake* h) { __atomic_store_n(&h->answered, 1, __ATOMIC_RELEASE); }

void handshake_wait_answer(handshake* h) {
  while (!__atomic_load_n(&h->answered, __ATOMIC_ACQUIRE)) sched_yield();
}
