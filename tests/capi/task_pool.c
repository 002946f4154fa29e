// SPDX-License-Identifier: MIT
#include "task_pool.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>

enum { kSlots = 16 };

typedef struct task_slot {
  sph_task_fn fn;
  void* context;
  uint32_t count, next, done;
  int in_use;
  int nested; /* enqueued from a pool thread */
} task_slot;

static struct {
  pthread_mutex_t mutex;
  pthread_cond_t work, finished;
  task_slot slots[kSlots];
  pthread_t threads[kTaskPoolThreads];
  int stop, running;
  atomic_int run_inline;
  atomic_uint tasks, items_on_pool, nested, nested_items_on_pool, inline_tasks;
} pool;

/* The pool's threads know themselves by this (their worker index + 1; 0 elsewhere). */
static __thread uint32_t pool_worker;

/* A broken promise of the library (or of this pool) ends the test at once, on any thread. */
static void require(int ok, const char* what) {
  if (ok) return;
  fprintf(stderr, "task_pool: %s\n", what);
  abort();
}

/* Runs one item of slot s; called and returns with the mutex held. */
static void run_item_locked(task_slot* s, uint32_t worker) {
  const uint32_t item = s->next++;
  const sph_task_fn fn = s->fn;
  void* context = s->context;
  pthread_mutex_unlock(&pool.mutex);
  fn(item, item + 1, worker, context);
  pthread_mutex_lock(&pool.mutex);
  if (++s->done == s->count) pthread_cond_broadcast(&pool.finished);
}

static task_slot* slot_with_work_locked(void) {
  int k;
  for (k = 0; k < kSlots; ++k)
    if (pool.slots[k].in_use && pool.slots[k].next < pool.slots[k].count) return &pool.slots[k];
  return NULL;
}

static void* pool_thread(void* arg) {
  const uint32_t worker = (uint32_t)(uintptr_t)arg;
  pool_worker = worker + 1;
  pthread_mutex_lock(&pool.mutex);
  while (!pool.stop) {
    task_slot* s = slot_with_work_locked();
    if (!s) {
      pthread_cond_wait(&pool.work, &pool.mutex);
      continue;
    }
    {
      const int nested = s->nested; /* (the slot may be reused once its last item is done) */
      run_item_locked(s, worker);
      atomic_fetch_add(&pool.items_on_pool, 1u);
      if (nested) atomic_fetch_add(&pool.nested_items_on_pool, 1u);
    }
  }
  pthread_mutex_unlock(&pool.mutex);
  return NULL;
}

static void* SPH_CALL enqueue_task(sph_task_fn task, uint32_t item_count, uint32_t min_range,
                                   void* task_context, void* user_context) {
  task_slot* s = NULL;
  int k;
  require(user_context == &pool, "enqueue_task: a foreign user_context");
  require(task != NULL && min_range >= 1u && item_count >= 1u, "enqueue_task: an empty task");
  if (pool_worker != 0) atomic_fetch_add(&pool.nested, 1u);
  pthread_mutex_lock(&pool.mutex);
  if (!atomic_load(&pool.run_inline))
    for (k = 0; k < kSlots && !s; ++k)
      if (!pool.slots[k].in_use) s = &pool.slots[k];
  if (!s) { /* asked to, or every slot busy: run it here (finish is then not called) */
    pthread_mutex_unlock(&pool.mutex);
    atomic_fetch_add(&pool.inline_tasks, 1u);
    task(0, item_count, pool_worker != 0 ? pool_worker - 1 : kTaskPoolThreads, task_context);
    return NULL;
  }
  s->fn = task;
  s->context = task_context;
  s->count = item_count;
  s->next = s->done = 0;
  s->in_use = 1;
  s->nested = pool_worker != 0;
  atomic_fetch_add(&pool.tasks, 1u);
  pthread_cond_broadcast(&pool.work);
  pthread_mutex_unlock(&pool.mutex);
  return s;
}

/* The caller helps with its own task's items, then waits for those the pool's threads run. */
static void SPH_CALL finish_task(void* user_task, void* user_context) {
  task_slot* s = (task_slot*)user_task;
  require(user_context == &pool, "finish_task: a foreign user_context");
  require(s >= pool.slots && s < pool.slots + kSlots, "finish_task: not a task of the pool");
  pthread_mutex_lock(&pool.mutex);
  require(s->in_use, "finish_task: the task was finished already");
  while (s->next < s->count) run_item_locked(s, pool_worker != 0 ? pool_worker - 1 : kTaskPoolThreads);
  while (s->done < s->count) pthread_cond_wait(&pool.finished, &pool.mutex);
  s->in_use = 0;
  pthread_mutex_unlock(&pool.mutex);
}

void task_pool_start(void) {
  int k;
  /* A test that failed before its task_pool_stop left worlds stepping on the pool: stop here
   * rather than hang. */
  require(!pool.running, "task_pool_start: the pool runs already (an earlier test failed?)");
  pool.running = 1;
  require(pthread_mutex_init(&pool.mutex, NULL) == 0, "pthread_mutex_init");
  require(pthread_cond_init(&pool.work, NULL) == 0, "pthread_cond_init");
  require(pthread_cond_init(&pool.finished, NULL) == 0, "pthread_cond_init");
  pool.stop = 0;
  atomic_store(&pool.run_inline, 0);
  atomic_store(&pool.tasks, 0u);
  atomic_store(&pool.items_on_pool, 0u);
  atomic_store(&pool.nested, 0u);
  atomic_store(&pool.nested_items_on_pool, 0u);
  atomic_store(&pool.inline_tasks, 0u);
  for (k = 0; k < kTaskPoolThreads; ++k)
    require(pthread_create(&pool.threads[k], NULL, pool_thread, (void*)(uintptr_t)k) == 0, "pthread_create");
}

void task_pool_stop(void) {
  int k;
  pthread_mutex_lock(&pool.mutex);
  for (k = 0; k < kSlots; ++k) require(!pool.slots[k].in_use, "task_pool_stop: a task was never finished");
  pool.stop = 1;
  pthread_cond_broadcast(&pool.work);
  pthread_mutex_unlock(&pool.mutex);
  for (k = 0; k < kTaskPoolThreads; ++k) pthread_join(pool.threads[k], NULL);
  pthread_cond_destroy(&pool.finished);
  pthread_cond_destroy(&pool.work);
  pthread_mutex_destroy(&pool.mutex);
  pool.running = 0;
}

void task_pool_use(sph_context_def* def) {
  def->enqueue_task = enqueue_task;
  def->finish_task = finish_task;
  def->task_user_context = &pool;
}

void task_pool_set_inline(int run_inline) { atomic_store(&pool.run_inline, run_inline); }

uint32_t task_pool_tasks(void) { return atomic_load(&pool.tasks); }
uint32_t task_pool_items_on_pool(void) { return atomic_load(&pool.items_on_pool); }
uint32_t task_pool_nested(void) { return atomic_load(&pool.nested); }
uint32_t task_pool_nested_items_on_pool(void) { return atomic_load(&pool.nested_items_on_pool); }
uint32_t task_pool_inline(void) { return atomic_load(&pool.inline_tasks); }
