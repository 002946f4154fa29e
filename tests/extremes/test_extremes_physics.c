// SPDX-License-Identifier: MIT
/* Physical extremes: stiffness over six decades, viscosity from 0 to very high, dt_max far
 * above the stable limit, velocities of 1e4 m/s, and the bound on the work of one call. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "extremes_util.h"

static ext_tank small_tank(void) {
  ext_tank t;
  memset(&t, 0, sizeof t);
  t.hx = 0.15f;
  t.hy = 0.1f;
  t.hz = 0.05f;
  t.column_width = 0.08f;
  t.column_height = 0.12f;
  return t;
}

static void print_measure(const char* what, double value, const ext_measure* m) {
  print_message(
      "  %s %-8g: n %u, |v|max %.3f m/s, energy gain %.3g of %.3g J, rho_max %.1f, depth %.4f m, "
      "largest dt %.3g s, substeps %u\n",
      what, value, m->count, m->max_speed, m->max_energy_gain, m->drop_energy, m->density_max, m->worst_depth,
      m->largest_dt, m->substeps);
}

/* The stable state of a dam break in the closed tank, whatever the parameters:
 * - every position, velocity and density finite, and no particle lost;
 * - no particle deeper than half a spacing in a wall (the scene tests' bound);
 * - the mechanical energy (kinetic + potential) never above its start by more than 1 % of the
 *   drop energy: viscosity, the clamped EOS and the walls (restitution 0) can only take energy
 *   out, so any gain is integration error, and an unstable step gains orders of magnitude;
 * - no particle faster than 2 sqrt(g H), Ritter's front speed of an ideal dam break of height H,
 *   the fastest a collapsing column runs;
 * - density at most rho0 (exp(g H / c^2) + 2 sqrt(g H) / c): the hydrostatic compression at the
 *   column's foot plus the water hammer (Joukowsky, drho = rho v / c) of the fastest front. */
static void expect_stable_dam_break(const ext_measure* m, uint32_t count, const ext_tank* t, float spacing,
                                    float sound_speed) {
  const float ritter = 2.0f * sqrtf(EXT_G * t->column_height);
  const float rho_band =
      1000.0f * (expf(EXT_G * t->column_height / (sound_speed * sound_speed)) + ritter / sound_speed);
  assert_true(m->finite);
  assert_int_equal(m->count, count);
  assert_true(m->worst_depth <= 0.5f * spacing);
  assert_true(m->max_energy_gain <= 0.01f * m->drop_energy);
  assert_true(m->max_speed <= ritter);
  assert_true(m->density_max <= rho_band);
}

static uint32_t particle_count(const ext_world* w) {
  uint32_t n = 0;
  EXT_OK(sph_world_get_particle_count(w->world, &n));
  return n;
}

/* Stiffness k = 1 ... 1e6 m^2/s^2 (sound speed 1 ... 1000 m/s) with the default dt_max: the
 * controller's acoustic ceiling (0.4 h / c) keeps every decade stable. Without it, k >= 1e5
 * gained 150x the drop energy (measured before the ceiling existed). */
static void test_stiffness_six_decades(void** state) {
  int decade;
  (void)state;
  for (decade = 0; decade <= 6; ++decade) {
    const float k = powf(10.0f, (float)decade);
    ext_world w;
    ext_tank t = small_tank();
    ext_measure m;
    uint32_t n;
    ext_open(&w, 1024, 0.02f);
    w.params.stiffness = k;
    ext_set_params(&w);
    ext_tank_build(&w, &t);
    n = particle_count(&w);
    m = ext_tank_run(&w, &t, 6, 1.0f / 60.0f);
    print_measure("k", k, &m);
    expect_stable_dam_break(&m, n, &t, 0.02f, sqrtf(k));
    ext_tank_destroy(&w, &t);
    ext_close(&w);
  }
}

/* Mueller viscosity mu = 0 ... 1e4 (kinematic 0 ... 10 m^2/s, ten thousand times glycerol's)
 * with the default dt_max: the viscous ceiling (0.05 h^2 rho0 / mu) keeps each stable. Without
 * it, mu >= 1e3 gained 600x the drop energy. */
static void test_viscosity_zero_to_very_high(void** state) {
  static const float mus[] = {0.0f, 1.0f, 1e2f, 1e3f, 1e4f};
  size_t c;
  (void)state;
  for (c = 0; c < sizeof mus / sizeof mus[0]; ++c) {
    ext_world w;
    ext_tank t = small_tank();
    ext_measure m;
    uint32_t n;
    ext_open(&w, 1024, 0.02f);
    w.params.viscosity = mus[c];
    w.params.stiffness = 1e3f;
    ext_set_params(&w);
    ext_tank_build(&w, &t);
    n = particle_count(&w);
    m = ext_tank_run(&w, &t, 3, 1.0f / 60.0f);
    print_measure("mu", mus[c], &m);
    expect_stable_dam_break(&m, n, &t, 0.02f, sqrtf(1e3f));
    ext_tank_destroy(&w, &t);
    ext_close(&w);
  }
}

/* mu = 1e9: the stable step 0.05 h^2 rho0 / mu is 6.5e-11 s. With dt_min lowered below it the
 * controller takes it, and a 1/60 s frame ends after max_substeps (SPH_INCOMPLETE, with the time
 * reached): bounded work, no hang. (dt_min is the caller's explicit floor and wins over the
 * ceiling: fixed-step runs pin dt_min = dt_max.) */
static void test_viscosity_extreme_work_is_bounded(void** state) {
  ext_world w;
  sph_stats st;
  float x[6] = {0.0f, 0.1f, 0.0f, 0.01f, 0.1f, 0.0f};
  (void)state;
  ext_open(&w, 16, 0.02f);
  ext_spawn(&w, x, NULL, 2);
  w.params.viscosity = 1e9f;
  w.params.dt_min = 1e-12f;
  w.params.max_substeps = 100;
  EXPECT_OK(sph_world_set_params(w.world, &w.params));
  assert_int_equal(sph_world_step(w.world, 1.0f / 60.0f), SPH_INCOMPLETE);
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  assert_int_equal(st.substeps, 100);
  assert_true(st.dt_max <= 0.05f * w.def.kernel_radius * w.def.kernel_radius * 1000.0f / 1e9f * 1.0001f);
  assert_true(st.frame_time < 1.0f / 60.0f);
  ext_close(&w);
}

/* dt_max from 1e-3 s to 100 s at k = 1e4 (c = 100 m/s): the controller never steps above the
 * acoustic ceiling 0.4 h / c = 1.44e-4 s and the dam break stays stable. Before the ceiling,
 * dt_max = 0.1 s flung particles 0.4 m through the walls. */
static void test_dt_max_far_above_stable_limit(void** state) {
  static const float dts[] = {1e-3f, 1e-2f, 1.0f, 100.0f};
  size_t c;
  (void)state;
  for (c = 0; c < sizeof dts / sizeof dts[0]; ++c) {
    ext_world w;
    ext_tank t = small_tank();
    ext_measure m;
    uint32_t n;
    float ceiling;
    ext_open(&w, 1024, 0.02f);
    ceiling = 0.4f * w.def.kernel_radius / 100.0f;
    w.params.stiffness = 1e4f;
    w.params.dt_max = dts[c];
    ext_set_params(&w);
    ext_tank_build(&w, &t);
    n = particle_count(&w);
    m = ext_tank_run(&w, &t, 3, 1.0f / 60.0f);
    print_measure("dt_max", dts[c], &m);
    expect_stable_dam_break(&m, n, &t, 0.02f, 100.0f);
    assert_true(m.largest_dt <= ceiling * 1.0001f);
    ext_tank_destroy(&w, &t);
    ext_close(&w);
  }
}

/* A 4 x 4 x 4 FCC block at 1e4 m/s in empty space (no gravity): uniform motion has no internal
 * forces, so every particle moves by v t exactly up to float rounding: ~700 substeps each
 * rounding to half an ulp at |x| <= 16 m (1e-6 m) bound the error by 1 mm. */
static void test_velocity_1e4_ballistic(void** state) {
  ext_world w;
  sph_fill_box_desc fill;
  sph_stats st;
  uint32_t n = 0, m = 0, i;
  float *x0, *x1;
  uint32_t *id0, *id1;
  (void)state;
  ext_open(&w, 256, 0.02f);
  w.params.gravity.y = 0.0f;
  ext_set_params(&w);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 0.06f;
  fill.velocity.x = 1e4f;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  x0 = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  id0 = (uint32_t*)ext_copy(w.world, SPH_ATTRIBUTE_ID, &n);
  EXPECT_OK(sph_world_step(w.world, 1e-3f));
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  print_message("  1e4 m/s: %u particles, %u substeps, dt %.3g..%.3g s\n", n, st.substeps, st.dt_min,
                st.dt_max);
  assert_true(st.substeps >= 600);
  x1 = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &m);
  id1 = (uint32_t*)ext_copy(w.world, SPH_ATTRIBUTE_ID, &m);
  assert_int_equal(m, n);
  for (i = 0; i < n; ++i) {
    uint32_t j = 0;
    while (j < n && id0[j] != id1[i]) ++j;
    assert_true(j < n);
    assert_true(fabsf(x1[3 * i] - (x0[3 * j] + 10.0f)) <= 1e-3f);
    assert_true(fabsf(x1[3 * i + 1] - x0[3 * j + 1]) <= 1e-3f);
    assert_true(fabsf(x1[3 * i + 2] - x0[3 * j + 2]) <= 1e-3f);
  }
  free(x0);
  free(x1);
  free(id0);
  free(id1);
  ext_close(&w);
}

/* The same block at 1e4 m/s needs 11,574 substeps for a 1/60 s frame (dt = 0.4 h / v): the
 * call returns SPH_INCOMPLETE after max_substeps (10,000 by default) with the time it reached,
 * instead of running on. */
static void test_velocity_1e4_work_is_bounded(void** state) {
  ext_world w;
  sph_fill_box_desc fill;
  sph_stats st;
  uint32_t n = 0;
  (void)state;
  ext_open(&w, 256, 0.02f);
  w.params.gravity.y = 0.0f;
  ext_set_params(&w);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 0.04f;
  fill.velocity.z = -1e4f;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  assert_int_equal(sph_world_step(w.world, 1.0f / 60.0f), SPH_INCOMPLETE);
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  assert_int_equal(st.substeps, 10000);
  assert_true(st.frame_time < 1.0f / 60.0f);
  assert_true(fabsf(st.frame_time - 10000.0f * 0.4f * w.def.kernel_radius / 1e4f) <= 1e-3f * st.frame_time);
  ext_close(&w);
}

/* A block thrown at 1e4 m/s at the tank's wall: the step size keeps each move below 0.4 h, the
 * collider catches every crossing, and no particle ends up deeper than half a spacing in the
 * wall; with restitution 0 nobody leaves faster than it came. */
static void test_velocity_1e4_into_wall(void** state) {
  ext_world w;
  ext_tank t = small_tank();
  sph_fill_box_desc fill;
  ext_measure m;
  uint32_t n = 0;
  (void)state;
  t.column_width = 0.04f;
  t.column_height = 0.04f;
  ext_open(&w, 256, 0.02f);
  ext_tank_build(&w, &t);
  sph_fill_box_desc_init(&fill);
  fill.min.x = 0.0f;
  fill.min.y = 0.1f;
  fill.min.z = -0.04f;
  fill.max.x = 0.06f;
  fill.max.y = 0.16f;
  fill.max.z = 0.04f;
  fill.velocity.x = 1e4f;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  EXT_OK(sph_world_get_particle_count(w.world, &n));
  m = ext_tank_run(&w, &t, 2, 1e-3f);
  print_measure("v", 1e4, &m);
  assert_true(m.finite);
  assert_int_equal(m.count, n);
  assert_true(m.worst_depth <= 0.5f * 0.02f);
  assert_true(m.max_speed <= 1e4f);
  ext_tank_destroy(&w, &t);
  ext_close(&w);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_stiffness_six_decades),
      cmocka_unit_test(test_viscosity_zero_to_very_high),
      cmocka_unit_test(test_viscosity_extreme_work_is_bounded),
      cmocka_unit_test(test_dt_max_far_above_stable_limit),
      cmocka_unit_test(test_velocity_1e4_ballistic),
      cmocka_unit_test(test_velocity_1e4_work_is_bounded),
      cmocka_unit_test(test_velocity_1e4_into_wall),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
