// SPDX-License-Identifier: MIT
/* The engine's threads and memory (issue 21, item 2): sph_context_def's task-system and
 * allocator hooks, on the CPU backend.
 *
 * 1. With a task system of the test's own (task_pool.c: three threads it starts itself), a
 *    world of about 5,800 particles (past the 4,096 where the loops go parallel) steps, and the
 *    library starts no thread: /proc/self/task lists as many threads after the frames as
 *    before the context, and the loops did run on the test's threads. The particles are bit for
 *    bit those of the same frames on the library's own OpenMP workers (run after, so no OpenMP
 *    thread existed during the first part). (Asynchronous steps on the task system:
 *    test_capi_async_task_step.c.)
 * 2. With a counting allocator, a world with a collider spawns, steps, saves and loads a
 *    checkpoint; the allocator holds at least the bytes sph_stats.memory_bytes reports, and none
 *    once the worlds and the SDF asset are destroyed.
 * 3. An allocator that gives nothing: spawn and step answer SPH_ERROR_OUT_OF_HOST_MEMORY and
 *    leave the world as it was; once it gives again, the same step succeeds.
 * 4. One context with both hooks used by three threads at once, each with its own world: every
 *    world ends bit for bit where the others do, and the allocator is empty after.
 * 5. Half-set hooks are refused with a message naming the missing field. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_async.h"
#include "sph_cuda.h"
#include "task_pool.h"

static const float kFrameDt = 1.0f / 60.0f;
enum { kFrames = 2, kWorldThreads = 3 };

/* ---- a counting allocator ---------------------------------------------------------------- */

static struct {
  atomic_llong live_bytes;
  atomic_uint allocations;
  atomic_int fail; /* nonzero: every alloc gives NULL */
} heap;

static void* SPH_CALL counting_alloc(size_t size, size_t alignment, void* user_context) {
  void* p = NULL;
  assert_ptr_equal(user_context, &heap);
  assert_true(size > 0 && alignment >= 16 && (alignment & (alignment - 1)) == 0);
  if (atomic_load(&heap.fail)) return NULL;
  if (posix_memalign(&p, alignment < sizeof(void*) ? sizeof(void*) : alignment, size) != 0) p = NULL;
  if (p) {
    atomic_fetch_add(&heap.live_bytes, (long long)size);
    atomic_fetch_add(&heap.allocations, 1u);
  }
  return p;
}

static void SPH_CALL counting_free(void* memory, size_t size, void* user_context) {
  assert_ptr_equal(user_context, &heap);
  atomic_fetch_sub(&heap.live_bytes, (long long)size);
  free(memory);
}

/* ---- scenes -------------------------------------------------------------------------------- */

static sph_context* make_context(int tasks, int allocator) {
  sph_context_def def;
  sph_context* context = NULL;
  EXPECT_OK(sph_context_def_init(&def));
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 4;
  if (tasks) task_pool_use(&def);
  if (allocator) {
    def.alloc_fn = counting_alloc;
    def.free_fn = counting_free;
    def.alloc_user_context = &heap;
  }
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

/* A block of about 5,800 particles falling in a box (a collider), so the loops run in parallel
 * and the collision response runs too. */
static sph_world* make_world_of(sph_context* context, float side, sph_sdf** box_sdf) {
  uint32_t added = 0;
  sph_world* world = capi_falling_block(context, 8192, side, &added);
  assert_true(side < 0.3f || added > 4096);
  if (box_sdf) {
    sph_shape_desc shape;
    sph_collider_def collider;
    sph_collider_id id;
    sph_shape_desc_init(&shape);
    shape.shape = SPH_SHAPE_BOX; /* a tank: hollow, open at the top, around the block */
    shape.half_extents.x = shape.half_extents.z = 0.25f;
    shape.half_extents.y = 0.3f;
    shape.wall_thickness = 0.04f;
    shape.flags = SPH_SHAPE_FLAG_OPEN_TOP;
    shape.voxel_size = 0.02f;
    EXPECT_OK(sph_sdf_create_shape(context, &shape, box_sdf));
    sph_collider_def_init(&collider);
    collider.sdf = *box_sdf;
    collider.transform.position.x = collider.transform.position.z = 0.16f;
    collider.transform.position.y = 0.2f;
    EXPECT_OK(sph_collider_create(world, &collider, &id));
  }
  return world;
}

static sph_world* make_world(sph_context* context, sph_sdf** box_sdf) {
  return make_world_of(context, 0.32f, box_sdf);
}

static void step_frames(sph_world* world) {
  int f;
  for (f = 0; f < kFrames; ++f) EXPECT_OK(sph_world_step(world, kFrameDt));
}

/* 1. No thread of the library's with the task hook, and the OpenMP path's bits. */
static void test_task_hook_starts_no_thread_and_matches_openmp(void** state) {
  sph_context *hooked, *openmp;
  sph_world *a, *b;
  int before;
  (void)state;
  task_pool_start();
  before = capi_thread_count();
  hooked = make_context(1, 0);
  a = make_world(hooked, NULL);
  step_frames(a);
  assert_int_equal(capi_thread_count(), before);
  assert_true(task_pool_tasks() > 10u);
  assert_true(task_pool_items_on_pool() > 0u);

  openmp = make_context(0, 0);
  b = make_world(openmp, NULL);
  step_frames(b);
  capi_expect_same_particles(a, b);
  EXPECT_OK(sph_world_destroy(b));
  EXPECT_OK(sph_world_destroy(a));
  EXPECT_OK(sph_context_destroy(openmp));
  EXPECT_OK(sph_context_destroy(hooked));
  task_pool_stop();
}

/* 2. Every allocation of the worlds and the SDF asset comes back. */
static void test_allocator_holds_the_world_and_gets_everything_back(void** state) {
  sph_context* context;
  sph_world *world, *copy;
  sph_sdf* box = NULL;
  sph_stats stats;
  (void)state;
  context = make_context(0, 1);
  assert_int_equal(atomic_load(&heap.live_bytes), 0);
  world = make_world(context, &box);
  step_frames(world);
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  assert_true(stats.memory_bytes > 0u);
  assert_true((uint64_t)atomic_load(&heap.live_bytes) >= stats.memory_bytes);
  copy = capi_world_copy(context, world);
  capi_expect_same_particles(world, copy);
  EXPECT_OK(sph_world_step(copy, kFrameDt));
  EXPECT_OK(sph_world_destroy(copy));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(box));
  assert_int_equal(atomic_load(&heap.live_bytes), 0);
  EXPECT_OK(sph_context_destroy(context));
}

/* 3. An allocator with nothing to give: clean refusals, the world unchanged. */
static void test_failing_allocator_leaves_the_world_unchanged(void** state) {
  static capi_snapshot before;
  sph_context* context;
  sph_world* world;
  sph_spawn_desc spawn;
  float positions[3 * 64];
  uint32_t first = 0;
  int k;
  (void)state;
  context = make_context(0, 1);
  world = make_world_of(context, 0.12f, NULL); /* about 300 particles: the snapshot holds 512 */
  EXPECT_OK(sph_world_step(world, kFrameDt));
  capi_snapshot_take(world, &before);
  for (k = 0; k < 64; ++k) {
    positions[3 * k] = 1.0f + 0.02f * (float)k;
    positions[3 * k + 1] = positions[3 * k + 2] = 1.0f;
  }
  sph_spawn_desc_init(&spawn);
  spawn.positions = positions;
  spawn.count = 64;
  atomic_store(&heap.fail, 1);
  EXPECT_ERROR(SPH_ERROR_OUT_OF_HOST_MEMORY, NULL, sph_world_step(world, kFrameDt));
  EXPECT_UNCHANGED(world, &before);
  EXPECT_ERROR(SPH_ERROR_OUT_OF_HOST_MEMORY, NULL, sph_world_spawn(world, &spawn, &first));
  EXPECT_UNCHANGED(world, &before);
  atomic_store(&heap.fail, 0);
  EXPECT_OK(sph_world_step(world, kFrameDt));
  EXPECT_OK(sph_world_destroy(world));
  assert_int_equal(atomic_load(&heap.live_bytes), 0);
  EXPECT_OK(sph_context_destroy(context));
}

/* 4. One hooked context, three threads, three worlds. */
typedef struct world_job {
  sph_context* context;
  sph_world* world;
} world_job;

static void* run_world(void* arg) {
  world_job* job = (world_job*)arg;
  job->world = make_world(job->context, NULL);
  step_frames(job->world);
  return NULL;
}

static void test_hooks_from_several_threads(void** state) {
  sph_context* context;
  pthread_t threads[kWorldThreads];
  world_job jobs[kWorldThreads];
  int k;
  (void)state;
  task_pool_start();
  context = make_context(1, 1);
  for (k = 0; k < kWorldThreads; ++k) {
    jobs[k].context = context;
    jobs[k].world = NULL;
    assert_int_equal(pthread_create(&threads[k], NULL, run_world, &jobs[k]), 0);
  }
  for (k = 0; k < kWorldThreads; ++k) pthread_join(threads[k], NULL);
  for (k = 1; k < kWorldThreads; ++k) capi_expect_same_particles(jobs[0].world, jobs[k].world);
  for (k = 0; k < kWorldThreads; ++k) EXPECT_OK(sph_world_destroy(jobs[k].world));
  assert_int_equal(atomic_load(&heap.live_bytes), 0);
  EXPECT_OK(sph_context_destroy(context));
  task_pool_stop();
}

/* 5. Half a hook is refused, naming the missing half. */
static void test_half_set_hooks_are_refused(void** state) {
  sph_context_def def;
  sph_context* context = NULL;
  (void)state;
  EXPECT_OK(sph_context_def_init(&def));
  task_pool_use(&def);
  def.finish_task = NULL;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->finish_task", sph_context_create(&def, &context));
  EXPECT_OK(sph_context_def_init(&def));
  task_pool_use(&def);
  def.enqueue_task = NULL;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->enqueue_task", sph_context_create(&def, &context));
  EXPECT_OK(sph_context_def_init(&def));
  def.alloc_fn = counting_alloc;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->free_fn", sph_context_create(&def, &context));
  EXPECT_OK(sph_context_def_init(&def));
  def.free_fn = counting_free;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->alloc_fn", sph_context_create(&def, &context));
  assert_null(context);
}

static void* SPH_CALL device_alloc(size_t size, int32_t device, void* user) {
  (void)size, (void)device, (void)user;
  return NULL;
}

/* The device allocator (sph_cuda.h): half of one is refused, and a CPU context has none. */
static void test_device_allocator_rules(void** state) {
  sph_cuda_allocator allocator;
  sph_context* context;
  (void)state;
  context = make_context(0, 0);
  EXPECT_OK(sph_cuda_allocator_init(&allocator));
  allocator.alloc_fn = device_alloc;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "allocator->free_fn",
               sph_cuda_context_set_allocator(context, &allocator));
  EXPECT_OK(sph_cuda_allocator_init(&allocator));
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "CUDA", sph_cuda_context_set_allocator(context, &allocator));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_cuda_context_set_allocator(NULL, &allocator));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_task_hook_starts_no_thread_and_matches_openmp),
      cmocka_unit_test(test_allocator_holds_the_world_and_gets_everything_back),
      cmocka_unit_test(test_failing_allocator_leaves_the_world_unchanged),
      cmocka_unit_test(test_hooks_from_several_threads),
      cmocka_unit_test(test_half_set_hooks_are_refused),
      cmocka_unit_test(test_device_allocator_rules),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
