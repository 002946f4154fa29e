// SPDX-License-Identifier: MIT
/* A task system of the tests' own, in the shape an engine gives one (sph_context_def's
 * enqueue_task / finish_task, Box2D v3's callbacks): a few threads the test starts itself, a
 * fixed table of tasks, items handed out one at a time. finish_task runs items of its own task
 * while it waits, so a task may enqueue tasks and finish them (the nesting an asynchronous step
 * on the task system needs) on any number of threads. One pool per process. */
#ifndef SPH_TASK_POOL_H
#define SPH_TASK_POOL_H

#include <stdint.h>

#include "sph_c.h"

enum { kTaskPoolThreads = 3 };

/* Starts the pool's threads and zeroes its counters; task_pool_stop joins them. */
void task_pool_start(void);
void task_pool_stop(void);
/* Sets def's enqueue_task, finish_task and task_user_context to the pool. */
void task_pool_use(sph_context_def* def);
/* Nonzero: enqueue_task runs every item itself and returns NULL (as Box2D allows). */
void task_pool_set_inline(int run_inline);

/* What the pool saw since task_pool_start. */
uint32_t task_pool_tasks(void);                /* tasks enqueued onto the pool (not those run inline) */
uint32_t task_pool_items_on_pool(void);        /* items the pool's own threads ran */
uint32_t task_pool_nested(void);               /* tasks enqueued from a pool thread (from inside a task) */
uint32_t task_pool_nested_items_on_pool(void); /* items of those nested tasks the pool's threads ran */
uint32_t task_pool_inline(void);               /* tasks enqueue_task ran itself */

#endif /* SPH_TASK_POOL_H */
