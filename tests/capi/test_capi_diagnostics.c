// SPDX-License-Identifier: MIT
/* Version queries, result strings, the thread-local last error and the log callback. */
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "capi_test.h"

static void test_version(void** state) {
  (void)state;
  assert_int_equal(sph_get_version(), SPH_VERSION);
  assert_int_equal(sph_get_abi_version(), SPH_ABI_VERSION);
  /* The packing the header documents: (major << 22) | (minor << 12) | patch. */
  assert_int_equal(SPH_VERSION >> 22, SPH_VERSION_MAJOR);
  assert_int_equal((SPH_VERSION >> 12) & 0x3ffu, SPH_VERSION_MINOR);
  assert_int_equal(SPH_VERSION & 0xfffu, SPH_VERSION_PATCH);
  assert_int_equal(SPH_ABI_VERSION, SPH_VERSION_MAJOR);
}

static void test_build_info(void** state) {
  char version[32];
  const char* info = sph_get_build_info();
  (void)state;
  assert_non_null(info);
  assert_true(strlen(info) > 0);
  snprintf(version, sizeof version, "%d.%d.%d", SPH_VERSION_MAJOR, SPH_VERSION_MINOR, SPH_VERSION_PATCH);
  assert_non_null(strstr(info, version));
  assert_non_null(strstr(info, "cpu"));         /* the CPU backend is always built */
  assert_ptr_equal(sph_get_build_info(), info); /* static */
}

static void test_result_strings(void** state) {
  static const struct {
    sph_result code;
    const char* name;
  } codes[] = {
      {SPH_INCOMPLETE, "SPH_INCOMPLETE"},
      {SPH_OK, "SPH_OK"},
      {SPH_ERROR_INVALID_ARGUMENT, "SPH_ERROR_INVALID_ARGUMENT"},
      {SPH_ERROR_INVALID_HANDLE, "SPH_ERROR_INVALID_HANDLE"},
      {SPH_ERROR_VERSION_MISMATCH, "SPH_ERROR_VERSION_MISMATCH"},
      {SPH_ERROR_UNSUPPORTED, "SPH_ERROR_UNSUPPORTED"},
      {SPH_ERROR_FEATURE_DISABLED, "SPH_ERROR_FEATURE_DISABLED"},
      {SPH_ERROR_CAPACITY, "SPH_ERROR_CAPACITY"},
      {SPH_ERROR_OUT_OF_HOST_MEMORY, "SPH_ERROR_OUT_OF_HOST_MEMORY"},
      {SPH_ERROR_OUT_OF_DEVICE_MEMORY, "SPH_ERROR_OUT_OF_DEVICE_MEMORY"},
      {SPH_ERROR_WORLD_LOCKED, "SPH_ERROR_WORLD_LOCKED"},
      {SPH_ERROR_BUSY, "SPH_ERROR_BUSY"},
      {SPH_ERROR_DEVICE, "SPH_ERROR_DEVICE"},
      {SPH_ERROR_DEVICE_LOST, "SPH_ERROR_DEVICE_LOST"},
      {SPH_ERROR_INTERNAL, "SPH_ERROR_INTERNAL"},
      {SPH_ERROR_BUFFER_TOO_SMALL, "SPH_ERROR_BUFFER_TOO_SMALL"},
      {SPH_ERROR_NON_FINITE, "SPH_ERROR_NON_FINITE"},
      {SPH_ERROR_CORRUPT_DATA, "SPH_ERROR_CORRUPT_DATA"},
  };
  const size_t n = sizeof codes / sizeof codes[0];
  const sph_result unknown[] = {(sph_result)2, (sph_result)-17, (sph_result)-1000, SPH_RESULT_FORCE32};
  (void)state;
  for (size_t i = 0; i < n; ++i) {
    const char* s = sph_result_string(codes[i].code);
    assert_non_null(s);
    /* Starts with the code's own name, followed by ':' (so "SPH_OK" is not "SPH_OK_X"). */
    assert_int_equal(strncmp(s, codes[i].name, strlen(codes[i].name)), 0);
    assert_int_equal(s[strlen(codes[i].name)], ':');
    for (size_t j = 0; j < i; ++j) assert_string_not_equal(s, sph_result_string(codes[j].code));
  }
  for (size_t u = 0; u < sizeof unknown / sizeof unknown[0]; ++u) {
    const char* s = sph_result_string(unknown[u]);
    assert_non_null(s);
    assert_true(strlen(s) > 0);
    for (size_t j = 0; j < n; ++j) assert_string_not_equal(s, sph_result_string(codes[j].code));
  }
}

static void test_last_error(void** state) {
  sph_context_def def;
  sph_context* context = NULL;
  uint32_t count = 0;
  (void)state;
  assert_string_equal(sph_get_last_error(), "");
  sph_context_def_init(&def);
  def.cuda_dfsph_masks = 7;
  assert_int_equal(sph_context_create(&def, &context), SPH_ERROR_INVALID_ARGUMENT);
  /* Names the function and the argument; stays until the next call. */
  assert_non_null(strstr(sph_get_last_error(), "sph_context_create"));
  assert_non_null(strstr(sph_get_last_error(), "cuda_dfsph_masks"));
  /* Any successful call clears it, including ones that cannot fail in interesting ways. */
  assert_int_equal(sph_get_live_object_count(&count), SPH_OK);
  assert_string_equal(sph_get_last_error(), "");
  assert_int_equal(sph_get_live_object_count(NULL), SPH_ERROR_INVALID_ARGUMENT);
  assert_true(strlen(sph_get_last_error()) > 0);
  assert_int_equal(sph_context_destroy(NULL), SPH_OK);
  assert_string_equal(sph_get_last_error(), "");
  assert_int_equal(sph_get_live_object_count(NULL), SPH_ERROR_INVALID_ARGUMENT);
  EXPECT_OK(sph_test_context_create(&context));
  EXPECT_OK(sph_context_destroy(context));
}

static void* fail_on_other_thread(void* arg) {
  sph_context_def def;
  sph_context* context = NULL;
  (void)arg;
  sph_context_def_init(&def);
  def.cpu_worker_count = 100000;
  if (sph_context_create(&def, &context) != SPH_ERROR_INVALID_ARGUMENT) return (void*)1;
  if (strstr(sph_get_last_error(), "cpu_worker_count") == NULL) return (void*)2;
  return NULL;
}

/* The last error is per thread: another thread's failure does not touch this thread's. */
static void test_last_error_thread_local(void** state) {
  pthread_t thread;
  void* result = (void*)99;
  (void)state;
  assert_int_equal(sph_get_live_object_count(NULL), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(sph_get_last_error(), "out_count"));
  assert_int_equal(pthread_create(&thread, NULL, fail_on_other_thread, NULL), 0);
  assert_int_equal(pthread_join(thread, &result), 0);
  assert_null(result);
  assert_non_null(strstr(sph_get_last_error(), "out_count"));
  assert_null(strstr(sph_get_last_error(), "cpu_worker_count"));
}

/* ---- the log callback ------------------------------------------------------------------------ */

typedef struct {
  int calls;
  sph_log_level level;
  sph_result code;
  char message[1024];
} log_record;

static void record_log(void* user_data, sph_log_level level, sph_result code, const char* message) {
  log_record* r = (log_record*)user_data;
  r->calls++;
  r->level = level;
  r->code = code;
  snprintf(r->message, sizeof r->message, "%s", message ? message : "(null)");
}

/* A test context whose log callback records into *log (cleared first). */
static sph_context* create_logging_context(log_record* log) {
  sph_context_def def;
  sph_context* context = NULL;
  memset(log, 0, sizeof *log);
  sph_test_context_def_init(&def);
  def.log_fn = record_log;
  def.log_user_data = log;
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

static void test_log_callback(void** state) {
  log_record log;
  sph_context* context = create_logging_context(&log);
  sph_world_def wdef;
  sph_world* world = NULL;
  sph_world_params params;
  (void)state;
  /* A failed world creation on this context is logged, with the same message. */
  sph_world_def_init(&wdef);
  wdef.capacity = 0xffffffffu;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "capacity", sph_world_create(context, &wdef, &world));
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.level, SPH_LOG_ERROR);
  assert_int_equal(log.code, SPH_ERROR_INVALID_ARGUMENT);
  assert_string_equal(log.message, sph_get_last_error());
  /* Successes are not logged as errors. */
  wdef.capacity = 32;
  EXPECT_OK(sph_world_create(context, &wdef, &world));
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_set_params(world, &params));
  EXPECT_OK(sph_world_step(world, 0.001f));
  assert_int_equal(log.calls, 1);
  /* A failed call on one of its worlds is logged too. */
  params.step_factor = -1.0f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "step_factor", sph_world_set_params(world, &params));
  assert_int_equal(log.calls, 2);
  assert_int_equal(log.level, SPH_LOG_ERROR);
  assert_int_equal(log.code, SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(log.message, "step_factor"));
  assert_string_equal(log.message, sph_get_last_error());
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(world, -1.0f));
  assert_int_equal(log.calls, 3);
  assert_non_null(strstr(log.message, "frame_dt"));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
  assert_int_equal(log.calls, 3);
}

/* One collider of an SDF made by sph_sdf_create_shape in a world of `features` (capi_collider_case:
 * spacing 2 cm, lattice step 1.414 cm); returns how many times the log callback was called meanwhile. */
static int collider_log_calls(sph_context* context, log_record* log, uint32_t features, sph_shape shape,
                              float voxel) {
  sph_world* world = NULL;
  sph_sdf* sdf = NULL;
  int before;
  capi_collider_case(context, features, shape, voxel, &world, &sdf);
  before = log->calls;
  EXPECT_OK(capi_add_collider(world, sdf));
  assert_string_equal(sph_get_last_error(), ""); /* a success, whatever it logged */
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(sdf));
  return log->calls - before;
}

/* With the walls in the density a collider whose SDF is coarser than half the lattice step
 * (here 7.07 mm) is a warning (SPH_LOG_WARNING, SPH_OK) naming the voxel; a finer one, a plane's
 * (exact at any voxel), or a world without the feature is not logged (docs/api.md, log_fn). */
static void test_log_coarse_sdf_warning(void** state) {
  log_record log;
  sph_context* context = create_logging_context(&log);
  (void)state;
  assert_int_equal(collider_log_calls(context, &log, SPH_FEATURE_BOUNDARY_DENSITY, SPH_SHAPE_BOX, 0.01f), 1);
  assert_int_equal(log.level, SPH_LOG_WARNING);
  assert_int_equal(log.code, SPH_OK);
  assert_non_null(strstr(log.message, "sph_collider_create"));
  assert_non_null(strstr(log.message, "0.01 m"));
  assert_non_null(strstr(log.message, "0.007071 m"));
  assert_int_equal(collider_log_calls(context, &log, SPH_FEATURE_BOUNDARY_DENSITY, SPH_SHAPE_BOX, 0.005f), 0);
  assert_int_equal(collider_log_calls(context, &log, SPH_FEATURE_BOUNDARY_DENSITY, SPH_SHAPE_PLANE, 0.01f),
                   0);
  assert_int_equal(collider_log_calls(context, &log, 0u, SPH_SHAPE_BOX, 0.01f), 0);
  EXPECT_OK(sph_context_destroy(context));
}

/* A world with the loads but not the walls in the density is a warning from sph_world_create
 * (SPH_LOG_WARNING, SPH_OK): its loads are the contact impulses alone, and a submerged body reads
 * almost none of its buoyancy (an engine programmer's review: 0.44 N for 9.81 N). Both features,
 * or neither, log nothing. */
static int world_create_log_calls(sph_context* context, log_record* log, uint32_t features) {
  sph_world_def def;
  sph_world* world = NULL;
  const int before = log->calls;
  sph_world_def_init(&def);
  def.capacity = 64;
  def.features = features;
  EXPECT_OK(sph_world_create(context, &def, &world));
  assert_string_equal(sph_get_last_error(), "");
  EXPECT_OK(sph_world_destroy(world));
  return log->calls - before;
}

static void test_log_loads_without_walls_warning(void** state) {
  log_record log;
  sph_context* context = create_logging_context(&log);
  (void)state;
  assert_int_equal(world_create_log_calls(context, &log, SPH_FEATURE_COLLIDER_LOADS), 1);
  assert_int_equal(log.level, SPH_LOG_WARNING);
  assert_int_equal(log.code, SPH_OK);
  assert_non_null(strstr(log.message, "sph_world_create"));
  assert_non_null(strstr(log.message, "SPH_FEATURE_BOUNDARY_DENSITY"));
  assert_int_equal(
      world_create_log_calls(context, &log, SPH_FEATURE_COLLIDER_LOADS | SPH_FEATURE_BOUNDARY_DENSITY), 0);
  assert_int_equal(world_create_log_calls(context, &log, 0u), 0);
  EXPECT_OK(sph_context_destroy(context));
}

/* A log callback that, on its first call, makes a call on `world` and keeps what that call
 * returned and the last error it left, then records every call's level: with `sdf` NULL a
 * failing step (a negative frame), otherwise a collider of `sdf` (a warning when it is coarse). */
typedef struct {
  int calls;
  sph_log_level levels[4];
  sph_world* world;
  sph_sdf* sdf;
  sph_result inner;
  char inner_error[1024];
} reentrant_log;

static void fail_inside_log(void* user_data, sph_log_level level, sph_result code, const char* message) {
  reentrant_log* r = (reentrant_log*)user_data;
  (void)code;
  (void)message;
  if (r->calls < 4) r->levels[r->calls] = level;
  if (r->calls++ == 0 && r->world) {
    r->inner = r->sdf ? capi_add_collider(r->world, r->sdf) : sph_world_step(r->world, -1.0f);
    snprintf(r->inner_error, sizeof r->inner_error, "%s", sph_get_last_error());
  }
}

/* Forgets the calls recorded so far; the world stays. */
static void rearm(reentrant_log* r) {
  r->calls = 0;
  r->inner = SPH_OK;
  r->inner_error[0] = '\0';
}

/* A call that fails inside the log callback returns its code and sets the last error as usual,
 * but is not reported to the callback again, whether the callback was telling of a failure or of
 * a warning (one flag for both; docs/api.md): the callback runs once per outer call. (Before,
 * each kind kept its own flag, so a failure inside a warning's callback was told to it again.) */
static void test_log_callback_no_recursion(void** state) {
  reentrant_log log;
  sph_context_def def;
  sph_context* context = NULL;
  sph_world_params params;
  sph_sdf* sdf = NULL;
  (void)state;
  memset(&log, 0, sizeof log);
  sph_test_context_def_init(&def);
  def.log_fn = fail_inside_log;
  def.log_user_data = &log;
  EXPECT_OK(sph_context_create(&def, &context));
  capi_coarse_collider_case(context, &log.world, &sdf);

  /* Inside a failure's callback. */
  sph_world_params_init(&params);
  params.step_factor = -1.0f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "step_factor", sph_world_set_params(log.world, &params));
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.levels[0], SPH_LOG_ERROR);
  assert_int_equal(log.inner, SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(log.inner_error, "frame_dt"));

  /* Inside a warning's callback (a collider whose SDF is coarser than half the lattice step). */
  rearm(&log);
  EXPECT_OK(capi_add_collider(log.world, sdf));
  assert_string_equal(sph_get_last_error(), ""); /* the outer call succeeded */
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.levels[0], SPH_LOG_WARNING);
  /* (the warning is told while sph_collider_create holds the world, so the inner step is refused
   * as WORLD_LOCKED before its frame is read) */
  assert_int_equal(log.inner, SPH_ERROR_WORLD_LOCKED);
  assert_non_null(strstr(log.inner_error, "sph_world_step"));

  /* Outside any callback, reporting goes on as before. */
  rearm(&log);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(log.world, -2.0f));
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.inner, SPH_ERROR_INVALID_ARGUMENT);

  /* A warning inside a failure's callback: the coarse collider is made (the failing call has
   * released the world by then) and its warning is not told. */
  rearm(&log);
  log.sdf = sdf;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(log.world, -2.0f));
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.levels[0], SPH_LOG_ERROR);
  assert_int_equal(log.inner, SPH_OK);
  assert_string_equal(log.inner_error, "");
  assert_non_null(strstr(sph_get_last_error(), "frame_dt")); /* the outer call's message again */
  EXPECT_OK(sph_world_destroy(log.world));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_version),
      cmocka_unit_test(test_build_info),
      cmocka_unit_test(test_result_strings),
      cmocka_unit_test(test_last_error),
      cmocka_unit_test(test_last_error_thread_local),
      cmocka_unit_test(test_log_callback),
      cmocka_unit_test(test_log_coarse_sdf_warning),
      cmocka_unit_test(test_log_loads_without_walls_warning),
      cmocka_unit_test(test_log_callback_no_recursion),
  };
  return cmocka_run_group_tests_name("capi_diagnostics", tests, NULL, NULL);
}
