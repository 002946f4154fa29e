// SPDX-License-Identifier: MIT
/* What the tests of asynchronous steps and of the engine's hooks share
 * (test_capi_async_step.c, test_capi_async_task_step.c, test_capi_engine_hooks.c): the process's
 * thread count, a falling block of fluid, waiting for a begun frame, and the two scenes both
 * asynchronous tests run on their own contexts (a frame cancelled while pending, a frame that
 * fails). */
#ifndef SPH_CAPI_ASYNC_H
#define SPH_CAPI_ASYNC_H

#include "capi_test.h"

/* The threads /proc/self/task lists, once the count holds still (capi_async.c). */
int capi_thread_count(void);

/* A world of `capacity` on `context` with a block of fluid [0, side]^3 (sph_world_fill_box, at
 * rest) in open space; *added (optional) receives its particle count. */
sph_world* capi_falling_block(sph_context* context, uint32_t capacity, float side, uint32_t* added);

/* Polls until the pending step is done (at most about 60 s); poll never runs the step. */
void capi_poll_until_done(const sph_world* world);

/* Gives the world many short substeps (dt_min = dt_max = 1e-4 s, up to 10,000 a frame) and begins
 * a frame of 0.5 s, likely still running while the checks that follow call into the world (their
 * answers must not depend on it: the world stays held until the wait): sph_world_step,
 * sph_world_step_begin, sph_world_get_particle_count, sph_world_set_params and
 * sph_world_destroy answer WORLD_LOCKED, destroying its context BUSY. */
void capi_begin_long_frame_and_expect_held(sph_context* context, sph_world* world);

/* With the frame of capi_begin_long_frame_and_expect_held pending: cancels it, waits, and checks
 * the result: SPH_INCOMPLETE before 5,000 substeps, or, if the frame already ran out (or, as a
 * CUDA frame on the device graph, cannot stop midway), the whole frame of 5,001 substeps and the
 * cancel waiting for the next step, which then stops at once. Prints "<what>: <result> after <n>
 * substeps". The world is free afterwards. */
void capi_expect_cancelled_frame(sph_world* world, const char* what);

/* A step that fails (8,000 particles piled into one cell: SPH_ERROR_CAPACITY) begun on a world of
 * `context` reports its error and message through the wait, the world is as before the begin,
 * and the failure was collected (no step pending). */
void capi_expect_failed_step_reported(sph_context* context);

#endif /* SPH_CAPI_ASYNC_H */
