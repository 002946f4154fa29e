// SPDX-License-Identifier: MIT
/* Clavet viscosity (SPH_VISCOSITY_CLAVET, thesis eq. 18-19): radial impulses between
 * approaching pairs, I = dt (1 - q)(sigma u + beta u^2), half to each particle. Issue 5: it
 * "damps relative motion and never adds energy". test_physics_options.c already checks, per
 * frame, that the kinetic energy of a random-velocity cloud never rises at sigma = 20, beta = 5
 * and falls below half an inviscid run's. This file adds what that does not cover:
 *   - one pair, head on: the impulse is the formula's (checked against it), and with large
 *     coefficients it stops the approach without reversing it (a pair has too few neighbours
 *     for the energy cap 4u / (n_i + n_j) to bind: before the cap at u this turned into an
 *     elastic bounce);
 *   - the linear and the quadratic coefficient each alone, and both large, on a random-velocity
 *     cloud and on two colliding streams: the kinetic energy of relative motion (in the centre
 *     of mass frame) never rises from one substep to the next, and momentum is conserved.
 * Pressure, gravity and Mueller viscosity are out of the way (stiffness 1e-6, below-rest
 * densities give zero pressure anyway), so only the impulses act. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "capi_test.h"

static const float kSpacing = 0.02f;
static const float kDt = 1e-3f;

static void open_clavet_world(float linear, float quadratic, uint32_t capacity, support_world* w) {
  sph_world_def def;
  sph_world_params p;
  sph_clavet_viscosity_params cp;
  sph_world_def_init(&def);
  def.particle_spacing = kSpacing;
  def.capacity = capacity;
  def.viscosity_method = SPH_VISCOSITY_CLAVET;
  sph_world_params_init(&p);
  p.gravity.y = 0.0f;
  p.stiffness = 1e-6f;
  p.dt_min = kDt; /* fixed substeps: one sph_world_step of kDt is one substep */
  p.dt_max = kDt;
  EXPECT_OK(support_world_open(w, sph_test_backend(), &def, &p));
  sph_clavet_viscosity_params_init(&cp);
  cp.linear = linear;
  cp.quadratic = quadratic;
  EXPECT_OK(sph_world_set_clavet_viscosity_params(w->world, &cp));
}

/* Two particles on the x axis, r = 0.5 h apart, closing at u = 1 m/s. After one substep the
 * closing speed is u - I with I from eq. 18-19 at the start of the substep (q = 0.5), capped at
 * u. Tolerances: float round-off of one velocity update (1e-5 m/s). */
static void test_pair_impulse_and_no_reversal(void** state) {
  const struct {
    float linear, quadratic;
  } cases[] = {{10.0f, 0.0f}, {0.0f, 20.0f}, {100.0f, 100.0f}, {1e4f, 0.0f}, {0.0f, 1e4f}, {1e6f, 1e6f}};
  (void)state;
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    support_world w;
    float x[6] = {0}, v[6] = {0}, *vout = NULL;
    const float u = 1.0f;
    double expected_impulse, closing;
    uint32_t count = 0;
    open_clavet_world(cases[c].linear, cases[c].quadratic, 16, &w);
    x[0] = -0.25f * w.def.kernel_radius;
    x[3] = 0.25f * w.def.kernel_radius;
    v[0] = 0.5f * u;
    v[3] = -0.5f * u;
    EXPECT_OK(support_spawn(w.world, x, v, 2));
    EXPECT_OK(sph_world_step(w.world, kDt));
    EXPECT_OK(support_copy_by_id(w.world, SPH_ATTRIBUTE_VELOCITY, (void**)&vout, &count));
    assert_int_equal(count, 2);
    closing = (double)vout[0] - vout[3];
    expected_impulse = kDt * 0.5 * (cases[c].linear * u + cases[c].quadratic * u * u);
    if (expected_impulse > u) expected_impulse = u;
    print_message("pair sigma %g beta %g: closing speed %.6f m/s after one substep (expected %.6f)\n",
                  cases[c].linear, cases[c].quadratic, closing, u - expected_impulse);
    assert_true(fabs(closing - (u - expected_impulse)) <= 1e-5);
    assert_true(closing >= -1e-5);                        /* never reversed */
    assert_true(fabs((double)vout[0] + vout[3]) <= 1e-6); /* momentum (equal masses) */
    assert_true(vout[1] == 0.0f && vout[2] == 0.0f && vout[4] == 0.0f && vout[5] == 0.0f);
    free(vout);
    EXPECT_OK(support_world_close(&w));
  }
}

typedef struct motion {
  double momentum[3];     /* sum m v */
  double relative_energy; /* sum 1/2 m |v - v_cm|^2 */
  double speed_sum;       /* sum m |v|: the scale of momentum round-off */
} motion;

static motion measure(const sph_world* world, float mass) {
  float* v = NULL;
  uint32_t n = 0;
  motion m = {{0.0, 0.0, 0.0}, 0.0, 0.0};
  double vcm[3];
  EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &n));
  for (uint32_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) m.momentum[k] += mass * (double)v[3 * i + k];
    m.speed_sum += mass * sqrt((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
                               (double)v[3 * i + 2] * v[3 * i + 2]);
  }
  for (int k = 0; k < 3; ++k) vcm[k] = m.momentum[k] / (mass * n);
  for (uint32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      m.relative_energy += 0.5 * mass * (v[3 * i + k] - vcm[k]) * (v[3 * i + k] - vcm[k]);
  free(v);
  return m;
}

/* scenario 0: an FCC ball of radius 6 s with random velocities in [-0.5, 0.5] m/s and a drift
 * of 0.3 m/s in x (so the centre-of-mass frame is not the lab frame); scenario 1: two FCC
 * balls of radius 4 s, 1.5 s apart, closing at 2 m/s. 60 substeps each. The energy of relative
 * motion may not rise by more than float round-off (1e-6 relative) in any substep, momentum may
 * not change by more than 1e-5 of sum m |v| (float sums over a thousand particles), and the
 * energy must fall (by at least 10 %) so the test cannot pass on impulses that never act. */
static void run_cloud(int scenario, float linear, float quadratic) {
  static const float drift[3] = {0.3f, 0.0f, 0.0f};
  support_world w;
  sph_world* world;
  float mass = 0.0f;
  float *a = NULL, *b = NULL, *x, *v;
  uint32_t na = 0, nb = 0, n;
  uint64_t rng = 7;
  motion m0, prev, m;
  int step;
  open_clavet_world(linear, quadratic, 4096, &w);
  world = w.world;
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  EXPECT_OK(support_fcc_sphere(NULL, (scenario == 0 ? 6.0f : 4.0f) * kSpacing, kSpacing, &a, &na));
  if (scenario == 1) EXPECT_OK(support_fcc_sphere(NULL, 4.0f * kSpacing, kSpacing, &b, &nb));
  n = na + nb;
  x = (float*)malloc(12 * (size_t)n);
  v = (float*)malloc(12 * (size_t)n);
  assert_true(x && v);
  /* the cloud: velocities in [-0.5, 0.5] m/s plus the drift; the streams: 1 m/s along x */
  if (scenario == 0) support_random_velocities(v, na, 0.5, drift, &rng);
  for (uint32_t i = 0; i < na; ++i)
    for (int k = 0; k < 3; ++k) {
      x[3 * i + k] = a[3 * i + k];
      if (scenario == 1) v[3 * i + k] = k == 0 ? 1.0f : 0.0f;
    }
  for (uint32_t i = 0; i < nb; ++i)
    for (int k = 0; k < 3; ++k) {
      /* the second ball's centre at 9.5 s: 1.5 s between the two surfaces */
      x[3 * (na + i) + k] = b[3 * i + k] + (k == 0 ? 9.5f * kSpacing : 0.0f);
      v[3 * (na + i) + k] = k == 0 ? -1.0f : 0.0f;
    }
  EXPECT_OK(support_spawn(world, x, v, n));
  m0 = prev = measure(world, mass);
  for (step = 0; step < 60; ++step) {
    EXPECT_OK(sph_world_step(world, kDt));
    m = measure(world, mass);
    if (!(m.relative_energy <= prev.relative_energy * (1.0 + 1e-6)))
      fail_msg("%s, sigma %g beta %g: relative kinetic energy rose from %.9g to %.9g J in substep %d",
               scenario ? "streams" : "cloud", linear, quadratic, prev.relative_energy, m.relative_energy,
               step + 1);
    for (int k = 0; k < 3; ++k) assert_true(fabs(m.momentum[k] - m0.momentum[k]) <= 1e-5 * m0.speed_sum);
    prev = m;
  }
  print_message("%s, sigma %g beta %g: relative kinetic energy %.4g -> %.4g J over 60 substeps\n",
                scenario ? "streams" : "cloud  ", linear, quadratic, m0.relative_energy, m.relative_energy);
  assert_true(m.relative_energy < 0.9 * m0.relative_energy);
  free(a);
  free(b);
  free(x);
  free(v);
  EXPECT_OK(support_world_close(&w));
}

static void test_relative_energy_never_rises(void** state) {
  /* sigma dt = 1 and beta u dt ~ 1 at u ~ 1 m/s: impulses at their caps, the case where an
   * uncapped or badly capped exchange would overshoot. */
  const struct {
    float linear, quadratic;
  } cases[] = {{20.0f, 0.0f}, {0.0f, 20.0f}, {1000.0f, 0.0f}, {0.0f, 1000.0f}, {1e5f, 1e5f}};
  (void)state;
  for (int scenario = 0; scenario < 2; ++scenario)
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c)
      run_cloud(scenario, cases[c].linear, cases[c].quadratic);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pair_impulse_and_no_reversal),
      cmocka_unit_test(test_relative_energy_never_rises),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
