// SPDX-License-Identifier: MIT
/* Contexts through the C API: every bad input to the context functions returns its code, names
 * the argument in sph_get_last_error(), writes no output and creates nothing. */
#include <string.h>

#include "capi_test.h"

/* A struct followed by bytes a newer header would have added. */
typedef struct {
  sph_context_def def;
  unsigned char extra[16];
} grown_context_def;

static uint32_t live_objects(void) {
  uint32_t n = 0xdeadbeefu;
  assert_int_equal(sph_get_live_object_count(&n), SPH_OK);
  return n;
}

/* sph_context_create must fail with (code, name), leave *out alone and create nothing. */
static void expect_create_fails_at(int line, const sph_context_def* def, sph_result code, const char* name) {
  sph_context* const sentinel = (sph_context*)(uintptr_t)0x1234;
  sph_context* out = sentinel;
  const uint32_t before = live_objects();
  EXPECT_ERROR_AT(line, code, name, sph_context_create(def, &out));
  assert_ptr_equal(out, sentinel);
  assert_int_equal(live_objects(), before);
}
#define EXPECT_CREATE_FAILS(...) expect_create_fails_at(__LINE__, __VA_ARGS__)

static void test_def_init(void** state) {
  sph_context_def def;
  grown_context_def grown;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def", sph_context_def_init_sized(NULL, sizeof def));
  /* Too small: an error, and nothing written. */
  memset(&def, 0xab, sizeof def);
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "def",
               sph_context_def_init_sized(&def, (uint32_t)(24 + 2 * sizeof(void*) - 4)));
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "def", sph_context_def_init_sized(&def, 0));
  assert_int_equal(def.struct_size, 0xababababu);
  /* A 0.1.0 caller's size (before the CUDA tuning fields): its prefix is filled, nothing past it. */
  EXPECT_OK(sph_context_def_init_sized(&def, (uint32_t)(24 + 2 * sizeof(void*))));
  assert_int_equal(def.struct_size, 24 + 2 * sizeof(void*));
  assert_int_equal(def.backend, SPH_BACKEND_AUTO);
  assert_int_equal(def.cuda_density_block, 0xababababu);
  /* The defaults the header documents. */
  EXPECT_OK(sph_context_def_init(&def));
  assert_int_equal(def.struct_size, sizeof def);
  assert_int_equal(def.header_version, SPH_VERSION);
  assert_int_equal(def.backend, SPH_BACKEND_AUTO);
  assert_int_equal(def.device_ordinal, -1);
  assert_int_equal(def.cpu_worker_count, 0);
  assert_int_equal(def.cuda_dfsph_masks, 0);
  assert_null(def.log_fn);
  assert_null(def.log_user_data);
  assert_int_equal(def.cuda_frames, SPH_CUDA_FRAMES_GRAPH);
  assert_int_equal(def.cuda_density_block, 0);
  assert_int_equal(def.cuda_force_block, 0);
  assert_int_equal(def.cuda_particle_lanes, 0);
  /* Larger (a newer caller): accepted, struct_size kept, the unknown tail zeroed. */
  memset(&grown, 0xab, sizeof grown);
  EXPECT_OK(sph_context_def_init_sized(&grown.def, sizeof grown));
  assert_int_equal(grown.def.struct_size, sizeof grown);
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0);
}

static void test_create_null_arguments(void** state) {
  sph_context_def def;
  sph_context* out = NULL;
  (void)state;
  sph_test_context_def_init(&def);
  EXPECT_CREATE_FAILS(NULL, SPH_ERROR_INVALID_ARGUMENT, "def");
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_context_create(&def, NULL));
  assert_int_equal(live_objects(), 0);
  /* And the same def works once the arguments are right. */
  EXPECT_OK(sph_context_create(&def, &out));
  assert_non_null(out);
  EXPECT_OK(sph_context_destroy(out));
}

static void test_create_struct_size(void** state) {
  grown_context_def grown;
  sph_context* out = NULL;
  (void)state;
  memset(&grown, 0, sizeof grown);
  sph_test_context_def_init(&grown.def);
  /* Below the struct's first released size (0.1.0: 24 + 2 pointers): refused. */
  grown.def.struct_size = (uint32_t)(24 + 2 * sizeof(void*) - 4);
  EXPECT_CREATE_FAILS(&grown.def, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  /* A 0.1.0 caller's struct, without the CUDA tuning fields that came later: accepted, the
     fields it lacks read as zero (the defaults), whatever the bytes after its struct hold. */
  grown.def.struct_size = (uint32_t)(24 + 2 * sizeof(void*));
  grown.def.cuda_density_block = 7; /* not a valid block size: it must not be read */
  EXPECT_OK(sph_context_create(&grown.def, &out));
  EXPECT_OK(sph_context_destroy(out));
  grown.def.cuda_density_block = 0;
  grown.def.struct_size = 0;
  EXPECT_CREATE_FAILS(&grown.def, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  /* Larger with a nonzero byte in the part this library does not know. */
  grown.def.struct_size = sizeof grown;
  grown.extra[9] = 1;
  EXPECT_CREATE_FAILS(&grown.def, SPH_ERROR_UNSUPPORTED, "struct_size");
  /* Larger with the unknown part zero: accepted. */
  grown.extra[9] = 0;
  EXPECT_OK(sph_context_create(&grown.def, &out));
  EXPECT_OK(sph_context_destroy(out));
}

static void test_create_header_version(void** state) {
  sph_context_def def;
  sph_context* out = NULL;
  (void)state;
  sph_test_context_def_init(&def);
  def.header_version = SPH_MAKE_VERSION(SPH_VERSION_MAJOR + 1, 0, 0);
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_VERSION_MISMATCH, "header_version");
  /* Same major, another minor: compatible by the versioning rule. */
  def.header_version = SPH_MAKE_VERSION(SPH_VERSION_MAJOR, SPH_VERSION_MINOR + 7, 3);
  EXPECT_OK(sph_context_create(&def, &out));
  EXPECT_OK(sph_context_destroy(out));
}

static void test_create_unknown_backend(void** state) {
  const int32_t bad[] = {3, 4, 1000, 0x7fffffff, -1};
  sph_context_def def;
  (void)state;
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    sph_test_context_def_init(&def);
    def.backend = (sph_backend)bad[i];
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_UNSUPPORTED, "backend");
  }
}

static void test_create_bad_fields(void** state) {
  sph_context_def def;
  (void)state;
  sph_test_context_def_init(&def);
  def.device_ordinal = -2;
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "device_ordinal");
  sph_test_context_def_init(&def);
  def.device_ordinal = INT32_MIN;
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "device_ordinal");
  sph_test_context_def_init(&def);
  def.cuda_dfsph_masks = 3; /* past SPH_CUDA_DFSPH_NEIGHBOR_LISTS */
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cuda_dfsph_masks");
  sph_test_context_def_init(&def);
  def.cuda_dfsph_masks = 0xffffffffu;
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cuda_dfsph_masks");
  sph_test_context_def_init(&def);
  def.cpu_worker_count = 0xffffffffu;
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cpu_worker_count");
}

/* The CUDA tuning fields are checked on every context (a CPU context ignores valid values): block
 * sizes are 0 or a power of two from 32 to 1024, cuda_frames one of its two values, the threads
 * per particle 0, 1, 2, 4 or 8. */
static void test_create_cuda_tuning(void** state) {
  static const uint32_t bad_blocks[] = {1, 16, 31, 33, 96, 100, 2048, 0x80000000u, 0xffffffffu};
  static const uint32_t good_blocks[] = {0, 32, 64, 128, 256, 512, 1024};
  static const uint32_t bad_lanes[] = {3, 5, 6, 7, 16, 32, 0x80000000u, 0xffffffffu};
  static const uint32_t good_lanes[] = {0, 1, 2, 4, 8};
  static const uint32_t bad_frames[] = {2, 0x7fffffffu, 0x80000000u};
  sph_context_def def;
  sph_context* context = NULL;
  size_t i;
  (void)state;
  for (i = 0; i < sizeof bad_blocks / sizeof bad_blocks[0]; ++i) {
    sph_test_context_def_init(&def);
    def.cuda_density_block = bad_blocks[i];
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cuda_density_block");
    sph_test_context_def_init(&def);
    def.cuda_force_block = bad_blocks[i];
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cuda_force_block");
  }
  for (i = 0; i < sizeof bad_frames / sizeof bad_frames[0]; ++i) {
    sph_test_context_def_init(&def);
    def.cuda_frames = (sph_cuda_frames)bad_frames[i];
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_UNSUPPORTED, "cuda_frames");
  }
  for (i = 0; i < sizeof bad_lanes / sizeof bad_lanes[0]; ++i) {
    sph_test_context_def_init(&def);
    def.cuda_particle_lanes = bad_lanes[i];
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_INVALID_ARGUMENT, "cuda_particle_lanes");
  }
  for (i = 0; i < sizeof good_lanes / sizeof good_lanes[0]; ++i) {
    sph_test_context_def_init(&def);
    def.cuda_particle_lanes = good_lanes[i];
    EXPECT_OK(sph_context_create(&def, &context));
    EXPECT_OK(sph_context_destroy(context));
  }
  /* The other values of cuda_dfsph_masks (a CPU context checks and ignores them). */
  sph_test_context_def_init(&def);
  def.cuda_dfsph_masks = SPH_CUDA_DFSPH_MASKS_OFF;
  EXPECT_OK(sph_context_create(&def, &context));
  EXPECT_OK(sph_context_destroy(context));
  sph_test_context_def_init(&def);
  def.cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS;
  EXPECT_OK(sph_context_create(&def, &context));
  EXPECT_OK(sph_context_destroy(context));
  for (i = 0; i < sizeof good_blocks / sizeof good_blocks[0]; ++i) {
    sph_test_context_def_init(&def);
    def.cuda_frames = SPH_CUDA_FRAMES_STREAM;
    def.cuda_density_block = good_blocks[i];
    def.cuda_force_block = good_blocks[sizeof good_blocks / sizeof good_blocks[0] - 1 - i];
    EXPECT_OK(sph_context_create(&def, &context));
    EXPECT_OK(sph_context_destroy(context));
  }
}

/* AUTO picks CUDA exactly when the library has CUDA and a usable device exists. */
static int cuda_device_present(void) {
  sph_context_def def;
  sph_context* context = NULL;
  sph_backend resolved = SPH_BACKEND_AUTO;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_AUTO;
  EXPECT_OK(sph_context_create(&def, &context));
  EXPECT_OK(sph_context_get_backend(context, &resolved));
  EXPECT_OK(sph_context_destroy(context));
  assert_true(resolved == SPH_BACKEND_CPU || resolved == SPH_BACKEND_CUDA);
  return resolved == SPH_BACKEND_CUDA;
}

/* On a machine without a GPU (or a build without CUDA), asking for CUDA is UNSUPPORTED. */
static void test_create_cuda_unavailable(void** state) {
  sph_context_def def;
  sph_context* context = NULL;
  (void)state;
  if (sph_test_backend() == SPH_BACKEND_CUDA) skip(); /* SPH_TEST_BACKEND=cuda: a GPU is expected */
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  if (cuda_device_present()) {
    print_message("a CUDA device is present: checking that CUDA creation succeeds instead\n");
    EXPECT_OK(sph_context_create(&def, &context));
    EXPECT_OK(sph_context_destroy(context));
  } else {
    EXPECT_CREATE_FAILS(&def, SPH_ERROR_UNSUPPORTED, "backend");
  }
}

/* A device ordinal past the last device is UNSUPPORTED on every machine. */
static void test_create_cuda_bad_ordinal(void** state) {
  sph_context_def def;
  (void)state;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  def.device_ordinal = 100000;
  /* With a device the ordinal is at fault; without one, the backend itself. */
  EXPECT_CREATE_FAILS(&def, SPH_ERROR_UNSUPPORTED, cuda_device_present() ? "device_ordinal" : "backend");
}

static void test_destroy(void** state) {
  sph_context* context = NULL;
  sph_context* stale = NULL;
  sph_world* world = NULL;
  sph_world* second = NULL;
  sph_world_def wdef;
  int foreign = 0;
  (void)state;
  EXPECT_OK(sph_context_destroy(NULL));
  /* Destroyed: INVALID_HANDLE, every time. */
  EXPECT_OK(sph_test_context_create(&stale));
  EXPECT_OK(sph_context_destroy(stale));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_destroy(stale));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_destroy(stale));
  /* Foreign pointers: a stack variable, and a world handed in as a context. */
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_destroy((sph_context*)(void*)&foreign));
  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&wdef);
  wdef.capacity = 16;
  EXPECT_OK(sph_world_create(context, &wdef, &world));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_destroy((sph_context*)(void*)world));
  /* Live worlds: BUSY, and the context keeps working. */
  EXPECT_ERROR(SPH_ERROR_BUSY, "context", sph_context_destroy(context));
  assert_int_equal(live_objects(), 2);
  EXPECT_OK(sph_world_create(context, &wdef, &second));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_ERROR(SPH_ERROR_BUSY, "context", sph_context_destroy(context));
  EXPECT_OK(sph_world_destroy(second));
  EXPECT_OK(sph_context_destroy(context));
  assert_int_equal(live_objects(), 0);
}

static void test_get_backend(void** state) {
  sph_context_def def;
  sph_context* context = NULL;
  sph_context* stale = NULL;
  sph_backend backend = SPH_BACKEND_FORCE32;
  int foreign = 0;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_get_backend(NULL, &backend));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context",
               sph_context_get_backend((const sph_context*)(void*)&foreign, &backend));
  assert_int_equal(backend, SPH_BACKEND_FORCE32);
  EXPECT_OK(sph_test_context_create(&stale));
  EXPECT_OK(sph_context_destroy(stale));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_context_get_backend(stale, &backend));

  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CPU;
  EXPECT_OK(sph_context_create(&def, &context));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_backend", sph_context_get_backend(context, NULL));
  EXPECT_OK(sph_context_get_backend(context, &backend));
  assert_int_equal(backend, SPH_BACKEND_CPU);
  EXPECT_OK(sph_context_destroy(context));

  /* The test backend resolves to CPU or CUDA, never AUTO. */
  EXPECT_OK(sph_test_context_create(&context));
  EXPECT_OK(sph_context_get_backend(context, &backend));
  assert_true(backend == SPH_BACKEND_CPU || backend == SPH_BACKEND_CUDA);
  if (sph_test_backend() != SPH_BACKEND_AUTO) assert_int_equal(backend, sph_test_backend());
  EXPECT_OK(sph_context_destroy(context));
}

static void test_live_object_count(void** state) {
  sph_context* a = NULL;
  sph_context* b = NULL;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_count", sph_get_live_object_count(NULL));
  assert_int_equal(live_objects(), 0);
  EXPECT_OK(sph_test_context_create(&a));
  EXPECT_OK(sph_test_context_create(&b));
  assert_int_equal(live_objects(), 2);
  EXPECT_OK(sph_context_destroy(a));
  assert_int_equal(live_objects(), 1);
  EXPECT_OK(sph_context_destroy(b));
  assert_int_equal(live_objects(), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_def_init),
      cmocka_unit_test(test_create_null_arguments),
      cmocka_unit_test(test_create_struct_size),
      cmocka_unit_test(test_create_header_version),
      cmocka_unit_test(test_create_unknown_backend),
      cmocka_unit_test(test_create_bad_fields),
      cmocka_unit_test(test_create_cuda_tuning),
      cmocka_unit_test(test_create_cuda_unavailable),
      cmocka_unit_test(test_create_cuda_bad_ordinal),
      cmocka_unit_test(test_destroy),
      cmocka_unit_test(test_get_backend),
      cmocka_unit_test(test_live_object_count),
  };
  return cmocka_run_group_tests_name("capi_context_errors", tests, NULL, NULL);
}
