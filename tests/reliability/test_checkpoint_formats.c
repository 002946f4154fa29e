// SPDX-License-Identifier: MIT
/* Checkpoint formats (issue 15): parameters are written per method from the methods' tables
 * (format version 2), version 1 files still load, and both go through the one validate() of the
 * set calls. tests/data/checkpoint_v1_options.sphckpt was written by the library of commit
 * 179918a (tests/data/make_checkpoint_v1.c says how): every option on, every parameter off its
 * default. When it was made, that library loaded it and stepped 3 frames to the same bits as this
 * one does (checked once by hand; here the v1 world and its v2 re-save must agree bit for bit). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

#ifndef SPH_TEST_DATA_DIR
#error "SPH_TEST_DATA_DIR must name tests/data"
#endif

#define V1_FILE SPH_TEST_DATA_DIR "/checkpoint_v1_options.sphckpt"
#define FRAME_DT (1.0f / 60.0f)

typedef struct formats_fixture {
  sph_context* context;
  uint8_t* v1;
  uint64_t v1_size;
} formats_fixture;

static uint8_t* read_file(const char* path, uint64_t* size) {
  FILE* f = fopen(path, "rb");
  long n;
  uint8_t* data;
  if (!f) fail_msg("cannot open %s", path);
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  data = (uint8_t*)malloc((size_t)n + 1);
  assert_non_null(data);
  assert_int_equal(fread(data, 1, (size_t)n, f), (size_t)n);
  fclose(f);
  *size = (uint64_t)n;
  return data;
}

static int setup(void** state) {
  static formats_fixture f;
  assert_int_equal(sph_test_context_create(&f.context), SPH_OK);
  f.v1 = read_file(V1_FILE, &f.v1_size);
  *state = &f;
  return 0;
}

static int teardown(void** state) {
  formats_fixture* f = (formats_fixture*)*state;
  free(f->v1);
  sph_context_destroy(f->context);
  return 0;
}

static uint32_t u32_at(const uint8_t* p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* FNV-1a 64 over the header without its checksum, then the payload (docs/checkpoint.md). */
static void reseal(uint8_t* data, size_t size) {
  uint64_t h = 0xcbf29ce484222325ull;
  size_t i;
  int k;
  for (i = 0; i < size; ++i) {
    if (i >= 32 && i < 40) continue;
    h ^= data[i];
    h *= 0x100000001b3ull;
  }
  for (k = 0; k < 8; ++k) data[32 + k] = (uint8_t)(h >> (8 * k));
}

/* The values make_checkpoint_v1.c set, read back through every getter. */
static void expect_generator_params(sph_world* w) {
  sph_world_params p;
  sph_surface_tension_params st;
  sph_clavet_viscosity_params cv;
  sph_tait_params tait;
  sph_spring_params sp;
  sph_world_def def;
  sph_world_def_init(&def);
  EXPECT_OK(sph_world_get_def(w, &def));
  assert_int_equal(def.capacity, 200);
  assert_int_equal(def.features,
                   SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_SPRINGS);
  assert_int_equal(def.integrator, SPH_INTEGRATOR_RK4);
  assert_int_equal(def.viscosity_method, SPH_VISCOSITY_CLAVET);
  assert_int_equal(def.equation_of_state, SPH_EOS_TAIT);
  assert_true(def.particle_spacing == 0.04f);
  sph_world_params_init(&p);
  EXPECT_OK(sph_world_get_params(w, &p));
  assert_int_equal(p.max_substeps, 5000);
  assert_true(p.gravity.x == 0.5f && p.gravity.y == -9.0f && p.gravity.z == 0.25f);
  assert_true(p.stiffness == 150.0f && p.viscosity == 0.75f && p.step_factor == 0.3f);
  assert_true(p.dt_min == 2e-6f && p.dt_max == 2e-3f);
  assert_int_equal(p.step_limits, SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE);
  sph_surface_tension_params_init(&st);
  EXPECT_OK(sph_world_get_surface_tension_params(w, &st));
  assert_true(st.coefficient == 0.05f && st.normal_threshold == 3.0f);
  sph_clavet_viscosity_params_init(&cv);
  EXPECT_OK(sph_world_get_clavet_viscosity_params(w, &cv));
  assert_true(cv.linear == 12.0f && cv.quadratic == 0.5f);
  sph_tait_params_init(&tait);
  EXPECT_OK(sph_world_get_tait_params(w, &tait));
  assert_true(tait.speed_of_sound == 12.0f);
  sph_spring_params_init(&sp);
  EXPECT_OK(sph_world_get_spring_params(w, &sp));
  assert_true(sp.stiffness == 2e3f && sp.link_radius == 0.05f && sp.yield_ratio == 0.2f &&
              sp.plasticity == 1.5f && sp.damping == 3.0f);
}

static void test_version_1_loads_into_the_new_params(void** state) {
  formats_fixture* f = (formats_fixture*)*state;
  sph_world *old_world = NULL, *resaved = NULL;
  uint64_t size = 0;
  uint8_t* v2;
  uint32_t count = 0;
  int frame;
  assert_int_equal(u32_at(f->v1 + 8), 1); /* the golden file is of format version 1 */
  EXPECT_OK(sph_world_load(f->context, f->v1, f->v1_size, &old_world));
  expect_generator_params(old_world);
  EXPECT_OK(sph_world_get_particle_count(old_world, &count));
  assert_int_equal(count, 87);
  /* Saved again, it is the current version (kFormatVersion, src/core/checkpoint_format.h: 15),
   * carries the same state and continues bit for bit alike. */
  assert_int_equal(sph_world_save(old_world, NULL, 0, &size), SPH_OK);
  v2 = (uint8_t*)malloc((size_t)size);
  EXPECT_OK(sph_world_save(old_world, v2, size, &size));
  assert_int_equal(u32_at(v2 + 8), 15);
  EXPECT_OK(sph_world_load(f->context, v2, size, &resaved));
  expect_generator_params(resaved);
  capi_expect_same_particles(old_world, resaved);
  for (frame = 0; frame < 3; ++frame) {
    EXPECT_OK(sph_world_step(old_world, FRAME_DT));
    EXPECT_OK(sph_world_step(resaved, FRAME_DT));
  }
  capi_expect_same_particles(old_world, resaved);
  EXPECT_OK(sph_world_destroy(old_world));
  EXPECT_OK(sph_world_destroy(resaved));
  free(v2);
}

/* Where `pattern` starts in data (with at least 4 bytes after it), or fails. */
static size_t find(const uint8_t* data, size_t size, const uint8_t* pattern, size_t n) {
  size_t i;
  for (i = 0; i + n + 4 <= size; ++i)
    if (memcmp(data + i, pattern, n) == 0) return i;
  fail_msg("pattern not found");
  abort();
}
/* Where the float that follows `pattern` sits in data, or fails. */
static size_t find_after(const uint8_t* data, size_t size, const uint8_t* pattern, size_t n) {
  return find(data, size, pattern, n) + n;
}

/* The shortest decimal that reads back as the same float, as the library writes values. */
static void shortest(float v, char* out, size_t size) {
  int digits;
  for (digits = 6; digits <= 9; ++digits) {
    snprintf(out, size, "%.*g", digits, (double)v);
    if (strtof(out, NULL) == v) return;
  }
}

static void expect_load_refused(formats_fixture* f, const uint8_t* data, uint64_t size, const char* message) {
  sph_world* out = NULL;
  char expected[256];
  assert_int_equal(sph_world_load(f->context, data, size, &out), SPH_ERROR_CORRUPT_DATA);
  assert_null(out);
  snprintf(expected, sizeof expected, "sph_world_load: checkpoint: section 'parameters': %s", message);
  if (strcmp(sph_get_last_error(), expected) != 0)
    fail_msg("message \"%s\", expected \"%s\"", sph_get_last_error(), expected);
}

/* Parameters out of range are refused by the checks of the set calls, in either version. */
static void test_both_versions_validate_through_the_set_rules(void** state) {
  formats_fixture* f = (formats_fixture*)*state;
  const float minus_one = -1.0f, two = 2.0f, tiny = 1e-7f;
  sph_world* world = NULL;
  uint64_t size = 0;
  uint8_t* data = (uint8_t*)malloc((size_t)f->v1_size);
  /* Version 1: the header (48), CONF (16 + 36), the PARM section header (16), then gravity (12)
   * and the stiffness. */
  const size_t v1_stiffness = 48 + 16 + 36 + 16 + 12;
  const uint8_t tait_block[] = {4, 0, 0, 0, 't', 'a', 'i', 't', 1, 0, 0, 0};
  const uint8_t springs_block[] = {7, 0, 0, 0, 's', 'p', 'r', 'i', 'n', 'g', 's', 5, 0, 0, 0};
  uint8_t* v2;
  size_t at;
  sph_world_def def;
  char h[32], message[160];
  memcpy(data, f->v1, (size_t)f->v1_size);
  memcpy(data + v1_stiffness, &minus_one, 4);
  reseal(data, (size_t)f->v1_size);
  expect_load_refused(f, data, f->v1_size, "ideal_gas.stiffness: must be > 0, got -1");
  free(data);

  EXPECT_OK(sph_world_load(f->context, f->v1, f->v1_size, &world));
  sph_world_def_init(&def);
  EXPECT_OK(sph_world_get_def(world, &def));
  shortest(def.kernel_radius, h, sizeof h);
  assert_int_equal(sph_world_save(world, NULL, 0, &size), SPH_OK);
  v2 = (uint8_t*)malloc((size_t)size);
  data = (uint8_t*)malloc((size_t)size);
  EXPECT_OK(sph_world_save(world, v2, size, &size));
  EXPECT_OK(sph_world_destroy(world));

  at = find_after(v2, (size_t)size, tait_block, sizeof tait_block);
  memcpy(data, v2, (size_t)size);
  memcpy(data + at, &minus_one, 4);
  reseal(data, (size_t)size);
  expect_load_refused(f, data, size, "tait.speed_of_sound: must be > 0, got -1");

  at = find_after(v2, (size_t)size, springs_block, sizeof springs_block);
  memcpy(data, v2, (size_t)size);
  memcpy(data + at + 8, &two, 4); /* yield_ratio, the third field */
  reseal(data, (size_t)size);
  expect_load_refused(f, data, size, "springs.yield_ratio: must be in [0, 1], got 2");
  memcpy(data, v2, (size_t)size);
  memcpy(data + at + 4, &two, 4); /* a link radius of 2 m, above h */
  reseal(data, (size_t)size);
  snprintf(message, sizeof message, "springs.link_radius: 2 m is above the kernel radius %s", h);
  expect_load_refused(f, data, size, message);

  /* The stepping block: dt_max (its fifth field, after max_substeps and a vec3) below dt_min. */
  {
    const uint8_t stepping_block[] = {8, 0, 0, 0, 's', 't', 'e', 'p', 'p', 'i', 'n', 'g', 6, 0, 0, 0};
    at = find_after(v2, (size_t)size, stepping_block, sizeof stepping_block);
    memcpy(data, v2, (size_t)size);
    memcpy(data + at + 4 + 12 + 4 + 4, &tiny, 4);
    reseal(data, (size_t)size);
    expect_load_refused(f, data, size, "stepping.dt_max: 1e-07 is smaller than stepping.dt_min 2e-06");
  }
  /* A method this library does not know, and a block with more fields than it knows. */
  at = find(v2, (size_t)size, tait_block, sizeof tait_block);
  memcpy(data, v2, (size_t)size);
  data[at + 7] = 'x'; /* "taix" */
  reseal(data, (size_t)size);
  expect_load_refused(f, data, size, "parameters of an unknown method 'taix'");
  memcpy(data, v2, (size_t)size);
  data[at + 8] = 2; /* two fields */
  reseal(data, (size_t)size);
  expect_load_refused(f, data, size, "'tait' has 2 fields; this library knows 1");
  free(data);
  free(v2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_version_1_loads_into_the_new_params),
      cmocka_unit_test(test_both_versions_validate_through_the_set_rules),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
