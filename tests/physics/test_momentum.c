// SPDX-License-Identifier: MIT
/* Linear momentum is conserved with no external force: the pressure and viscosity pair forces
 * are antisymmetric (equal and opposite for each pair), so sum(m a) = 0 at every force
 * evaluation, for symplectic Euler and for each RK4 stage alike. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "capi_test.h"

static void momentum(const sph_world* world, double p[3], double* sum_abs) {
  float* v = NULL;
  float mass = 0.0f;
  uint32_t n = 0;
  EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &n));
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  p[0] = p[1] = p[2] = 0.0;
  *sum_abs = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    const double vx = v[3 * i], vy = v[3 * i + 1], vz = v[3 * i + 2];
    p[0] += mass * vx;
    p[1] += mass * vy;
    p[2] += mass * vz;
    *sum_abs += mass * sqrt(vx * vx + vy * vy + vz * vz);
  }
  free(v);
}

/* A blob of ~740 particles (an FCC ball of radius 5 spacings) with a common drift plus random
 * velocities; no gravity; `frames` frames of 0.1 s at a fixed dt of 1 ms. */
static void run(sph_integrator integrator, int frames) {
  const float drift_velocity[3] = {0.3f, -0.2f, 0.1f};
  support_world w;
  sph_world_def def;
  sph_world_params params;
  sph_stats stats;
  double p0[3], p1[3], abs0, abs1, drift;
  uint32_t substeps = 0, n = 0;
  /* velocity components uniform in drift + [-0.5, 0.5] m/s */
  support_sphere ball = {{0.0, 0.0, 0.0}, 0.1f, 0.0, 0.5, NULL, 0x9e3779b97f4a7c15ull, 0};
  sph_world* world;
  ball.drift = drift_velocity;

  sph_world_def_init(&def);
  def.capacity = 0; /* the ball's particles */
  def.integrator = integrator;
  /* dt fixed at 1 ms: sqrt(k) dt = 0.01 m < 0.4 h, and the speeds stay ~1 m/s. */
  EXPECT_OK(support_params_gravity_and_steps(&params, 0.0f, 0.0f, 0.0f, 1e-3f, 1e-3f));
  EXPECT_OK(support_rest_sphere_open(&w, sph_test_backend(), &def, &params, &ball, &n));
  world = w.world;
  momentum(world, p0, &abs0);
  for (int f = 0; f < frames; ++f) {
    EXPECT_OK(sph_world_step(world, 0.1f));
    sph_stats_init(&stats);
    EXPECT_OK(sph_world_get_stats(world, &stats));
    substeps += stats.substeps;
  }
  momentum(world, p1, &abs1);
  drift = sqrt((p1[0] - p0[0]) * (p1[0] - p0[0]) + (p1[1] - p0[1]) * (p1[1] - p0[1]) +
               (p1[2] - p0[2]) * (p1[2] - p0[2]));
  {
    const double p0_norm = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
    printf(
        "%s: %u particles, %u substeps, |P0| = %.6g, sum |m v| = %.6g -> %.6g, |P1 - P0| = %.3g "
        "(%.2e of |P0|)\n",
        integrator == SPH_INTEGRATOR_RK4 ? "RK4" : "symplectic Euler", n, substeps, p0_norm, abs0, abs1,
        drift, drift / p0_norm);
    /* The blob must actually have interacted: the pair forces changed the individual
     * momenta (viscosity damps the random part), while their sum stayed put. */
    assert_true(fabs(abs1 - abs0) > 1e-3 * abs0);
    assert_true(substeps >= 1000);
    /* Exact conservation would give 0. Float rounding of each velocity update (~6e-8 of |v|,
     * random in sign) and of the force sums (the i-j and j-i terms are computed separately)
     * drifts the sum like a random walk: ~sqrt(N substeps) x 6e-8 |v| ~ 5e-5 |v| against
     * |P0| ~ 0.4 N |v|, i.e. ~1e-7 relative. 1e-5 (the bound) leaves two orders of
     * magnitude and still catches any asymmetric force term (a missing 1/2, rho_i vs rho_j,
     * a one-sided neighbour list), which breaks conservation by percents. */
    assert_true(drift < 1e-5 * p0_norm);
  }
  EXPECT_OK(support_world_close(&w));
}

static void test_momentum_symplectic_euler(void** state) {
  (void)state;
  run(SPH_INTEGRATOR_SYMPLECTIC_EULER, 10); /* 1,000 substeps */
}

static void test_momentum_rk4(void** state) {
  (void)state;
  run(SPH_INTEGRATOR_RK4, 10); /* 1,000 substeps, 4,000 force evaluations */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_momentum_symplectic_euler),
      cmocka_unit_test(test_momentum_rk4),
  };
  return cmocka_run_group_tests_name("momentum", tests, NULL, NULL);
}
