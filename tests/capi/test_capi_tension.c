// SPDX-License-Identifier: MIT
/* sph_world_params.tension_ratio, the equation of state's bounded tension (docs/api.md, physics.md):
 * - defaults: _init writes 0 (the clamp at zero), a zeroed struct keeps 0, a world starts at 0;
 * - round trip: values of [0, 0.125] set read back bit for bit, and survives a checkpoint;
 * - errors: negative, above 0.125, NaN, Inf are INVALID_ARGUMENT naming the field, the world unchanged;
 * - a caller built against the 48-byte struct of 0.1.0 (no tension_ratio) is read with tau 0 and
 *   gets 48 bytes back;
 * - what it does: on a weakly compressible world a ball's surface (below rho0) pulls, so the
 *   particles move differently from tau 0 after one frame; on a DFSPH world (no equation of state)
 *   it is accepted and has no effect: the same bits as tau 0 after three frames. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

#define FRAME_DT (1.0f / 60.0f)

static sph_world* ball_world(sph_context* context, sph_solver solver, float tau) {
  sph_world_def def;
  sph_world_params p;
  sph_fill_sphere_desc sphere;
  sph_world* world = NULL;
  uint32_t added = 0;
  sph_world_def_init(&def);
  def.capacity = 2048;
  def.particle_spacing = 0.02f;
  def.solver = solver;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_params_init(&p);
  p.gravity.y = 0.0f;
  p.tension_ratio = tau;
  EXPECT_OK(sph_world_set_params(world, &p));
  sph_fill_sphere_desc_init(&sphere);
  sphere.radius = 0.1f;
  EXPECT_OK(sph_world_fill_sphere(world, &sphere, &added));
  assert_true(added > 400);
  return world;
}

static float tension_of(const sph_world* world) {
  sph_world_params p;
  sph_world_params_init(&p);
  EXPECT_OK(sph_world_get_params(world, &p));
  return p.tension_ratio;
}

static void test_defaults(void** state) {
  sph_context* context = NULL;
  sph_world* world;
  sph_world_params p;
  (void)state;
  memset(&p, 0xab, sizeof p);
  EXPECT_OK(sph_world_params_init(&p));
  assert_int_equal(p.struct_size, 52);
  assert_true(p.tension_ratio == 0.0f && !signbit(p.tension_ratio));
  EXPECT_OK(sph_test_context_create(&context));
  world = ball_world(context, SPH_SOLVER_WCSPH, 0.0f);
  sph_world_params_init(&p);
  EXPECT_OK(sph_world_set_params(world, &p)); /* a fresh struct resets the world: tau 0 */
  assert_true(tension_of(world) == 0.0f);
  memset(&p, 0, sizeof p);
  p.struct_size = sizeof p;
  EXPECT_OK(sph_world_set_params(world, &p)); /* zero is a value: the clamp */
  assert_true(tension_of(world) == 0.0f);
  sph_world_destroy(world);
  sph_context_destroy(context);
}

static void test_round_trip_and_checkpoint(void** state) {
  const float values[] = {0.0f, 1e-6f, 0.005f, 0.02f, 0.05f, 0.1f, 0.125f};
  sph_context* context = NULL;
  sph_world *world, *copy;
  size_t i;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  world = ball_world(context, SPH_SOLVER_WCSPH, 0.0f);
  for (i = 0; i < sizeof values / sizeof values[0]; ++i) {
    sph_world_params p;
    float got;
    sph_world_params_init(&p);
    EXPECT_OK(sph_world_get_params(world, &p));
    p.tension_ratio = values[i];
    EXPECT_OK(sph_world_set_params(world, &p));
    got = tension_of(world);
    assert_memory_equal(&got, &values[i], sizeof got);
  }
  /* The checkpoint carries it (format 11, the wcsph block of PARM), and the copy steps alike. */
  {
    sph_world_params p;
    sph_world_params_init(&p);
    EXPECT_OK(sph_world_get_params(world, &p));
    p.tension_ratio = 0.02f;
    EXPECT_OK(sph_world_set_params(world, &p));
  }
  EXPECT_OK(sph_world_step(world, FRAME_DT));
  copy = capi_world_copy(context, world);
  assert_true(tension_of(copy) == 0.02f);
  EXPECT_OK(sph_world_step(world, FRAME_DT));
  EXPECT_OK(sph_world_step(copy, FRAME_DT));
  capi_expect_same_particles(world, copy);
  sph_world_destroy(copy);
  sph_world_destroy(world);
  sph_context_destroy(context);
}

static void test_bad_values_leave_the_world_unchanged(void** state) {
  const struct {
    float value;
    const char* message;
  } bad[] = {
      {-0.01f, "sph_world_set_params: params->tension_ratio: must be in [0, 0.125], got -0.01"},
      {0.13f, "sph_world_set_params: params->tension_ratio: must be in [0, 0.125], got 0.13"},
      {1.0f, "sph_world_set_params: params->tension_ratio: must be in [0, 0.125], got 1"},
      {NAN, "sph_world_set_params: params->tension_ratio: is not finite"},
      {INFINITY, "sph_world_set_params: params->tension_ratio: is not finite"},
      {-INFINITY, "sph_world_set_params: params->tension_ratio: is not finite"},
  };
  sph_context* context = NULL;
  sph_world* world;
  sph_world_params before, p, after;
  size_t i;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  world = ball_world(context, SPH_SOLVER_WCSPH, 0.03f);
  sph_world_params_init(&before);
  EXPECT_OK(sph_world_get_params(world, &before));
  for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    p = before;
    p.viscosity = 0.25f; /* a valid change beside it must not land either */
    p.tension_ratio = bad[i].value;
    assert_int_equal(sph_world_set_params(world, &p), SPH_ERROR_INVALID_ARGUMENT);
    assert_string_equal(sph_get_last_error(), bad[i].message);
    sph_world_params_init(&after);
    EXPECT_OK(sph_world_get_params(world, &after));
    assert_memory_equal(&before, &after, sizeof before);
  }
  /* The bound itself is accepted; the next float past it is not. */
  p = before;
  p.tension_ratio = nextafterf(0.125f, 1.0f);
  assert_int_equal(sph_world_set_params(world, &p), SPH_ERROR_INVALID_ARGUMENT);
  p.tension_ratio = 0.125f;
  EXPECT_OK(sph_world_set_params(world, &p));
  sph_world_destroy(world);
  sph_context_destroy(context);
}

/* A caller of 0.1.0's header: struct_size 48, no tension_ratio. */
static void test_a_caller_of_the_48_byte_struct(void** state) {
  sph_context* context = NULL;
  sph_world* world;
  unsigned char old[60];
  uint32_t size = 48;
  sph_world_params p;
  float viscosity = 0.5f, marker;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  world = ball_world(context, SPH_SOLVER_WCSPH, 0.05f);
  /* _init_sized with 48 fills 48 bytes and leaves the rest alone. */
  memset(old, 0xcd, sizeof old);
  EXPECT_OK(sph_world_params_init_sized((sph_world_params*)(void*)old, 48));
  assert_int_equal(old[48], 0xcd);
  memcpy(&p, old, 48);
  assert_int_equal(p.struct_size, 48);
  assert_true(p.stiffness == 100.0f && p.dt_max == 1e-3f);
  /* Set with 48 bytes: the field it lacks reads as 0, the old behaviour (the clamp). */
  memcpy(old + offsetof(sph_world_params, viscosity), &viscosity, sizeof viscosity);
  EXPECT_OK(sph_world_set_params(world, (const sph_world_params*)(const void*)old));
  assert_true(tension_of(world) == 0.0f);
  /* Read with 48 bytes: nothing past them is written. */
  memset(old, 0xcd, sizeof old);
  memcpy(old, &size, sizeof size);
  EXPECT_OK(sph_world_get_params(world, (sph_world_params*)(void*)old));
  assert_int_equal(old[48], 0xcd);
  memcpy(&marker, old + offsetof(sph_world_params, viscosity), sizeof marker);
  assert_true(marker == 0.5f);
  /* Below the first released size: VERSION_MISMATCH, before anything is written. */
  memset(old, 0xcd, sizeof old);
  size = 44;
  memcpy(old, &size, sizeof size);
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "is smaller than 48",
               sph_world_set_params(world, (const sph_world_params*)(const void*)old));
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "is smaller than 48",
               sph_world_params_init_sized((sph_world_params*)(void*)old, 44));
  assert_int_equal(old[4], 0xcd);
  sph_world_destroy(world);
  sph_context_destroy(context);
}

/* The surface of a ball at rest sits below rho0: with a tension it pulls inward, without it
 * nothing acts there. So one frame moves the particles differently, and the tension (a
 * negative pressure) shows in SPH_ATTRIBUTE_PRESSURE. */
static void test_it_acts_on_a_weakly_compressible_world(void** state) {
  sph_context* context = NULL;
  sph_world *clamp, *pull;
  uint32_t n = 0, i, negative = 0;
  float *a, *b, *pressure, most_negative = 0.0f;
  double moved = 0.0;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  clamp = ball_world(context, SPH_SOLVER_WCSPH, 0.0f);
  pull = ball_world(context, SPH_SOLVER_WCSPH, 0.02f);
  EXPECT_OK(sph_world_step(clamp, FRAME_DT));
  EXPECT_OK(sph_world_step(pull, FRAME_DT));
  EXPECT_OK(sph_world_get_particle_count(pull, &n));
  a = (float*)calloc(3u * n, sizeof(float));
  b = (float*)calloc(3u * n, sizeof(float));
  pressure = (float*)calloc(n, sizeof(float));
  assert_true(a && b && pressure);
  EXPECT_OK(sph_world_copy_attribute(clamp, SPH_ATTRIBUTE_POSITION, a, 12ull * n, 0, 0, n, NULL));
  EXPECT_OK(sph_world_copy_attribute(pull, SPH_ATTRIBUTE_POSITION, b, 12ull * n, 0, 0, n, NULL));
  for (i = 0; i < 3u * n; ++i) moved += fabs((double)a[i] - (double)b[i]);
  assert_true(moved > 0.0);
  EXPECT_OK(sph_world_copy_attribute(clamp, SPH_ATTRIBUTE_PRESSURE, pressure, 4ull * n, 0, 0, n, NULL));
  for (i = 0; i < n; ++i) assert_true(pressure[i] >= 0.0f); /* tau 0: the clamp */
  EXPECT_OK(sph_world_copy_attribute(pull, SPH_ATTRIBUTE_PRESSURE, pressure, 4ull * n, 0, 0, n, NULL));
  for (i = 0; i < n; ++i) {
    negative += pressure[i] < 0.0f;
    if (pressure[i] < most_negative) most_negative = pressure[i];
  }
  /* Bounded by the law at the floor: -k tau rho0 = -100 * 0.02 * 1000 = -2000 Pa (a float's
   * rounding of (1 - tau) rho0 aside). */
  assert_true(negative > 0);
  assert_true(most_negative >= -2000.0f * (1.0f + 1e-5f));
  free(a);
  free(b);
  free(pressure);
  sph_world_destroy(clamp);
  sph_world_destroy(pull);
  sph_context_destroy(context);
}

static void test_no_effect_with_dfsph(void** state) {
  sph_context* context = NULL;
  sph_world *clamp, *pull;
  int f;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  clamp = ball_world(context, SPH_SOLVER_DFSPH, 0.0f);
  pull = ball_world(context, SPH_SOLVER_DFSPH, 0.1f); /* accepted */
  assert_true(tension_of(pull) == 0.1f);
  for (f = 0; f < 3; ++f) {
    EXPECT_OK(sph_world_step(clamp, FRAME_DT));
    EXPECT_OK(sph_world_step(pull, FRAME_DT));
  }
  capi_expect_same_particles(clamp, pull);
  sph_world_destroy(clamp);
  sph_world_destroy(pull);
  sph_context_destroy(context);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults),
      cmocka_unit_test(test_round_trip_and_checkpoint),
      cmocka_unit_test(test_bad_values_leave_the_world_unchanged),
      cmocka_unit_test(test_a_caller_of_the_48_byte_struct),
      cmocka_unit_test(test_it_acts_on_a_weakly_compressible_world),
      cmocka_unit_test(test_no_effect_with_dfsph),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
