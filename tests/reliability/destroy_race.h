// SPDX-License-Identifier: MIT
/* What the destroy-race test's threads share (test_destroy_race.c): a tally of the results each
 * thread saw, the start signal, the pauses between an intruder's calls, and the handshake of the
 * held rounds.
 *
 * Worker threads never call cmocka (its failure path longjmps): they record, the main thread
 * checks. */
#ifndef SPH_TESTS_DESTROY_RACE_H
#define SPH_TESTS_DESTROY_RACE_H

#include <pthread.h>

#include "capi_test.h"

enum { kParticles = 8 };

/* Results one thread saw, by kind. */
typedef struct tally {
  long ok, locked, invalid, busy, other;
  sph_result first_other;
  char first_other_message[200];
} tally;

void tally_add(tally* t, sph_result r);
void tally_merge(tally* into, const tally* t);
/* Fails the test (main thread only) if `t` saw anything but the expected results. */
void expect_no_other(const char* who, const tally* t);

/* A CPU-worker-light context (the race is between API calls, not inside a step), and a world of
 * kParticles particles on it (NULL on failure, with the last error set). */
sph_context* create_context(void);
sph_world* create_world(sph_context* context);

/* The start signal of a round: threads wait on `go` under `mutex`. */
int wait_go(pthread_mutex_t* mutex, volatile int* go);

/* Gaps between an intruder's calls, so the destroyer finds the object free now and then; wider
 * ones once `slow` is set (threads calling back to back can hold an object for seconds on 2 busy
 * cores). `slow` (may be NULL) is read relaxed: the flag must not order the intruders' calls
 * after the destroyer's (that would hide from ThreadSanitizer the very race under test). */
void pause_between_calls(const int* slow);

/* The held rounds. Whether the free rounds ever meet a call inside the object is luck: on a
 * loaded machine, where the process has about one core, the destroyer runs while the intruders
 * wait for a core, between their calls, and a call of a few microseconds is almost never caught
 * half done (0 rounds of 2,000 under `taskset -c 0`, where "destroy met a call" was asserted).
 * In a held round the intruder posts once it holds the object (a step begun, a world alive on a
 * context, a collider made), and waits for the destroyer's answer; the destroyer waits for the
 * post, destroys, and answers. The waits end on events that must come (no timeouts); they order
 * only this one destroy after the hold, while the free rounds stay unordered. */
typedef struct handshake {
  sph_result seen; /* what the holder's call returned, written before `posted` */
  int posted;      /* set (release) by the holder */
  int answered;    /* set (release) by the destroyer once its destroy returned */
} handshake;

/* Rounds 0, kHeldEvery, 2 kHeldEvery, ... are held; kHeldEvery is even: the SDF test's held
 * rounds need the collider maker of its even rounds. */
enum { kHeldEvery = 8 };
static inline int held_round(int round) { return round % kHeldEvery == 0; }
static inline long held_rounds(int rounds) { return (rounds + kHeldEvery - 1) / kHeldEvery; }

void handshake_post(handshake* h, sph_result seen);
/* Spins (yielding) until posted; returns what the holder saw. */
sph_result handshake_wait_post(handshake* h);
void handshake_answer(handshake* h);
void handshake_wait_answer(handshake* h);

#endif /* SPH_TESTS_DESTROY_RACE_H */
