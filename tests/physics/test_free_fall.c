// SPDX-License-Identifier: MIT
/* A single particle (no neighbours, so no pressure or viscosity) falls freely: after time t
 * its height is y = -g t^2 / 2 up to each integrator's error. Symplectic Euler is first order
 * (x_n = -g t^2/2 - g t dt/2, so halving dt halves the error); RK4 is exact for a constant
 * acceleration, so only float rounding remains. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "capi_test.h"

#define G 9.81

typedef struct {
  double t;    /* simulated time */
  double x, y; /* final position */
  double vx, vy;
  uint32_t substeps;
} fall;

/* Starts at the origin with horizontal velocity 1 m/s and falls for 1 s at a fixed dt. */
static fall run(sph_integrator integrator, float dt) {
  support_world w;
  sph_world_def def;
  sph_stats stats;
  const float position[3] = {0.0f, 0.0f, 0.0f};
  const float velocity[3] = {1.0f, 0.0f, 0.0f};
  float x[3], v[3];
  fall out;
  sph_world_def_init(&def);
  def.capacity = 1;
  def.integrator = integrator;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  /* dt_min = dt_max: a fixed step */
  EXPECT_OK(support_set_gravity_and_steps(w.world, 0.0f, (float)-G, 0.0f, dt, dt));
  EXPECT_OK(support_spawn(w.world, position, velocity, 1));
  EXPECT_OK(sph_world_step(w.world, 1.0f));
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(w.world, &stats));
  EXPECT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_POSITION, x, sizeof x, 0, 0, 1, NULL));
  EXPECT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 1, NULL));
  EXPECT_OK(support_world_close(&w));
  out.t = stats.simulated_time;
  out.x = x[0];
  out.y = x[1];
  out.vx = v[0];
  out.vy = v[1];
  out.substeps = stats.substeps;
  assert_true(fabs(out.t - 1.0) < 1e-9);
  assert_true(x[2] == 0.0f && v[2] == 0.0f);
  return out;
}

static double exact_y(double t) { return -0.5 * G * t * t; }

static void test_symplectic_euler_first_order(void** state) {
  const fall coarse = run(SPH_INTEGRATOR_SYMPLECTIC_EULER, 0.01f);
  const fall fine = run(SPH_INTEGRATOR_SYMPLECTIC_EULER, 0.005f);
  const double e_coarse = coarse.y - exact_y(coarse.t), e_fine = fine.y - exact_y(fine.t);
  const double ratio = e_coarse / e_fine;
  (void)state;
  printf("symplectic Euler: error %.6g m at dt 0.01 s (%u substeps), %.6g m at dt 0.005 s; ratio %.4f\n",
         e_coarse, coarse.substeps, e_fine, ratio);
  assert_true(coarse.substeps >= 100 && fine.substeps >= 200);
  /* The leading error is -g t dt / 2 (0.049 m and 0.0245 m): float rounding (~1e-5 m over a
   * few hundred steps) and the short landing step at the frame's end change it by < 0.1 %;
   * 2 % tells a first-order method from anything else. */
  assert_true(fabs(e_coarse / (-0.5 * G * coarse.t * 0.01) - 1.0) < 0.02);
  assert_true(fabs(e_fine / (-0.5 * G * fine.t * 0.005) - 1.0) < 0.02);
  /* The bound: halving dt halves the error, ratio within [1.8, 2.2]. */
  assert_true(ratio >= 1.8 && ratio <= 2.2);
  /* Velocity is exact for a constant acceleration (v_n = n g dt), up to float rounding; the
   * horizontal motion is uniform. 1e-5 is ~40 float steps at these magnitudes. */
  assert_true(fabs(coarse.vy + G * coarse.t) < 1e-5 * G);
  assert_true(fabs(coarse.x - coarse.t) < 1e-5 && fabs(coarse.vx - 1.0) < 1e-6);
}

static void test_rk4_exact_for_constant_acceleration(void** state) {
  const float dts[] = {0.01f, 0.005f, 0.05f};
  (void)state;
  for (size_t i = 0; i < sizeof dts / sizeof dts[0]; ++i) {
    const fall r = run(SPH_INTEGRATOR_RK4, dts[i]);
    const double error = r.y - exact_y(r.t);
    /* Only float rounding: each substep rounds y (|y| < 5 m, where a float step is 4.8e-7 m)
     * a few times, so n substeps stay within n x 2e-6 m. Symplectic Euler's error at the
     * same dt is ~0.5 g dt, four orders of magnitude larger. */
    const double bound = r.substeps * 2e-6;
    printf("RK4: dt %.3f s (%u substeps): error %.3g m (float bound %.3g m, Euler's would be %.3g m)\n",
           dts[i], r.substeps, error, bound, 0.5 * G * dts[i]);
    assert_true(fabs(error) < bound);
    assert_true(fabs(r.vy + G * r.t) < 1e-5 * G);
    assert_true(fabs(r.x - r.t) < 1e-5 && fabs(r.vx - 1.0) < 1e-6);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_symplectic_euler_first_order),
      cmocka_unit_test(test_rk4_exact_for_constant_acceleration),
  };
  return cmocka_run_group_tests_name("free_fall", tests, NULL, NULL);
}
