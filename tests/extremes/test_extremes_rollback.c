// SPDX-License-Identifier: MIT
/* A step that produces non-finite values (issue 9 item 3): SPH_ERROR_NON_FINITE with a message
 * that names the stage and the particles, the world bitwise as it was before the step (every
 * attribute copied out before and after and compared with memcmp), the same failure again on a
 * retry, and the caller can go on with a smaller dt. Provoked with valid input: uniform force
 * fields of 3e38 m/s^2 (finite each; two of them add up to +Inf, one gives a velocity whose
 * square overflows within a 1e-3 s step but not within a 1e-21 s one). And a non-finite value
 * that moves nothing: a lone particle (no neighbours, no pressure force) in a world whose rest
 * density (1e38 kg/m^3, valid) makes Tait's pressure overflow; the step fails in the density stage
 * rather than leave an infinite pressure in the world (which its own checkpoint would refuse to
 * load: found by fuzz_capi). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "extremes_util.h"

typedef struct world_copy {
  uint32_t count;
  void* attributes[SPH_ATTRIBUTE_ID + 1]; /* the user attribute needs a feature these worlds lack */
  double simulated_time;
} world_copy;

static world_copy take_copy(const sph_world* world) {
  world_copy c;
  sph_stats st;
  int a;
  for (a = 0; a <= SPH_ATTRIBUTE_ID; ++a) c.attributes[a] = ext_copy(world, (sph_attribute)a, &c.count);
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(world, &st));
  c.simulated_time = st.simulated_time;
  return c;
}

static void expect_same_bits(const world_copy* before, const world_copy* after) {
  int a;
  assert_int_equal(after->count, before->count);
  assert_memory_equal(&after->simulated_time, &before->simulated_time, sizeof(double));
  for (a = 0; a <= SPH_ATTRIBUTE_ID; ++a) {
    const size_t element = (a == SPH_ATTRIBUTE_POSITION || a == SPH_ATTRIBUTE_VELOCITY) ? 12 : 4;
    assert_int_equal(memcmp(before->attributes[a], after->attributes[a], element * before->count), 0);
  }
}

static void free_copy(world_copy* c) {
  int a;
  for (a = 0; a <= SPH_ATTRIBUTE_ID; ++a) free(c->attributes[a]);
}

static sph_force_field_id add_uniform_field(ext_world* w, float ax) {
  sph_force_field_def d;
  sph_force_field_id id;
  sph_force_field_def_init(&d);
  d.kind = SPH_FORCE_FIELD_UNIFORM;
  d.vector.x = ax;
  EXT_OK(sph_force_field_create(w->world, &d, &id));
  return id;
}

/* Steps, expects SPH_ERROR_NON_FINITE naming `stage`, and checks the world did not change. */
static void expect_rolled_back_step(ext_world* w, const char* stage, uint32_t count, char* message,
                                    size_t message_size) {
  world_copy before = take_copy(w->world), after;
  char particles[64];
  EXPECT_ERROR(SPH_ERROR_NON_FINITE, stage, sph_world_step(w->world, 1e-3f));
  print_message("  %s\n", sph_get_last_error());
  snprintf(particles, sizeof particles, "%u particle%s, ", count, count == 1 ? "" : "s");
  assert_non_null(strstr(sph_get_last_error(), particles));
  assert_non_null(strstr(sph_get_last_error(), "restored"));
  snprintf(message, message_size, "%s", sph_get_last_error());
  after = take_copy(w->world);
  expect_same_bits(&before, &after);
  free_copy(&before);
  free_copy(&after);
}

static void run_rollback_case(sph_integrator integrator) {
  ext_world w;
  sph_world_def def;
  sph_fill_box_desc fill;
  sph_force_field_id a, b;
  uint32_t n = 0;
  char first[1024], second[1024];
  sph_world_def_init(&def);
  def.capacity = 256;
  def.integrator = integrator;
  ext_open_def(&w, def);
  /* The force step limit reads the last |a|max: a rollback must restore it too, or the retry
   * would take another dt (and name it in its message). */
  w.params.step_limits = SPH_STEP_LIMIT_FORCE;
  ext_set_params(&w);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 0.08f;
  fill.velocity.x = 0.3f;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  /* A few frames first, so that order, densities and pressures are no longer the initial ones. */
  EXPECT_OK(sph_world_step(w.world, 0.01f));
  EXPECT_OK(sph_world_step(w.world, 0.01f));

  /* Two finite fields whose sum overflows: every acceleration is +Inf. */
  a = add_uniform_field(&w, 3e38f);
  b = add_uniform_field(&w, 3e38f);
  expect_rolled_back_step(&w, "forces stage", n, first, sizeof first);
  expect_rolled_back_step(&w, "forces stage", n, second, sizeof second);
  assert_string_equal(first, second); /* the same substep, dt and particles again */

  /* One field: a finite acceleration, but v = a dt = 3e35 m/s has |v|^2 = Inf. */
  EXT_OK(sph_force_field_destroy(w.world, b));
  expect_rolled_back_step(&w, "integrate", n, first, sizeof first);

  /* Going on with a smaller step: in 1e-21 s the speed reaches 3e17 m/s, |v|^2 = 9e34 fits. */
  w.params.dt_min = 1e-21f;
  w.params.dt_max = 1e-21f;
  ext_set_params(&w);
  EXPECT_OK(sph_world_step(w.world, 1e-21f));
  EXT_OK(sph_force_field_destroy(w.world, a));
  ext_close(&w);
}

/* The lone particle: Tait's law with rho0 = 1e38 kg/m^3 has B = rho0 c^2 / 7 = +Inf (c 10 m/s), so
 * its pressure is not finite (Inf times the zero of (rho / rho0)^7 - 1 at rest), while, with no
 * neighbour to push, its motion is. */
static void run_lone_particle_case(sph_integrator integrator) {
  ext_world w;
  sph_world_def def;
  const float x[3] = {0.0f, 0.0f, 0.0f}, v[3] = {0.1f, 0.0f, 0.0f};
  char message[1024];
  float* pressure;
  uint32_t n = 0;
  sph_world_def_init(&def);
  def.capacity = 16;
  def.rest_density = 1e38f;
  def.equation_of_state = SPH_EOS_TAIT;
  def.integrator = integrator;
  ext_open_def(&w, def);
  w.params.gravity.y = 0.0f;
  ext_set_params(&w);
  ext_spawn(&w, x, v, 1);
  expect_rolled_back_step(&w, "density stage", 1, message, sizeof message);
  /* The world as it was: its pressure finite, and its own checkpoint loads. */
  pressure = (float*)ext_copy(w.world, SPH_ATTRIBUTE_PRESSURE, &n);
  assert_int_equal(n, 1);
  assert_true(isfinite(pressure[0]));
  free(pressure);
  sph_world_destroy(capi_world_copy(w.context, w.world));
  ext_close(&w);
}

static void test_non_finite_pressure_rolls_back_euler(void** state) {
  (void)state;
  run_lone_particle_case(SPH_INTEGRATOR_SYMPLECTIC_EULER);
}

static void test_non_finite_pressure_rolls_back_rk4(void** state) {
  (void)state;
  run_lone_particle_case(SPH_INTEGRATOR_RK4);
}

static void test_non_finite_step_rolls_back_euler(void** state) {
  (void)state;
  run_rollback_case(SPH_INTEGRATOR_SYMPLECTIC_EULER);
}

static void test_non_finite_step_rolls_back_rk4(void** state) {
  (void)state;
  run_rollback_case(SPH_INTEGRATOR_RK4);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_non_finite_step_rolls_back_euler),
      cmocka_unit_test(test_non_finite_step_rolls_back_rk4),
      cmocka_unit_test(test_non_finite_pressure_rolls_back_euler),
      cmocka_unit_test(test_non_finite_pressure_rolls_back_rk4),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
