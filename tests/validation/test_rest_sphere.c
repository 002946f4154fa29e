// SPDX-License-Identifier: MIT
/* The thesis's rest sphere (its Figure 8 benchmark; ../shared/BENCHMARK.md case 1): an FCC ball
 * at rest density, no gravity, no colliders, water defaults, the default kernel radius, 100
 * frames at 25 frames/s with dt_max = 1 ms.
 *
 * Runs (argv[1]):
 * - rest: the case, the benchmark's sphere as specified: zero start velocity. Every
 *   bound below applies. It fails if the density sum is miscalibrated (the interior would not
 *   sit at rho0), if the free surface is unstable (an EOS with tension flings surface particles
 *   off at metres per second) or if the forces have a bias that sets the ball moving.
 * - disturbed: random start velocities of up to 1 mm/s, so that every term works: the kinetic
 *   energy must decay and the radius stay within 2 %. Its interior density is reported.
 * - disturbed_density (a known issue): the same run with the density bounds. The equation of
 *   state has no tension (methods.h), so every local compression of the disturbance
 *   pushes particles apart and nothing pulls them back: the ball swells until its interior sits
 *   about 2.4 % below rho0, while its kinetic energy decays. That is the model (a fluid without
 *   cohesion), not a numerical fault; BENCHMARK.md's "moving" run at +-0.1 m/s disperses the
 *   ball outright (radius +17 % in 0.4 s), as a drop without surface tension would.
 * - disturbed_tension: the disturbed run with the density bounds, a bounded tension
 *   (tension_ratio 0.005) and the normalised density: it holds rho0 within 0.1 % (below).
 *
 * Bounds (the issue's), and why they are the right ones:
 * - interior density (particles more than 2 h inside the surface, where the kernel sees a full
 *   neighbourhood): mean error <= 1 %, worst particle <= 2 %, at every frame. A weakly
 *   compressible fluid at rest should sit at rho0; the 1 %/2 % is the usual WCSPH density
 *   budget (a speed of sound ten times the flow speed).
 * - kinetic energy decaying: the last frame's kinetic energy below the start's, and the second
 *   half's peak below the first half's. A fluid at rest with viscosity loses the disturbance;
 *   an instability (the sphere ringing, expanding or collapsing) pumps it up instead. At zero
 *   start velocity (rest): the second half's peak below the first's, and no particle faster
 *   than 1 mm/s at the end (BENCHMARK.md: "the sphere must also stay at rest").
 * - radius change <= 2 %: the radius of gyration (sqrt(3/5) R for a uniform ball) against its
 *   start. A drop without cohesion may swell by the surface layer's deficit at most. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "validation_util.h"

#define FRAMES 100

typedef struct sphere_case {
  const char* name;
  double disturbance;   /* start speeds uniform in [-d, d] per component, m/s */
  int check_density;    /* assert the interior density bounds */
  sph_solver solver;    /* 0: the weakly compressible scheme */
  uint32_t dfsph_flags; /* sph_dfsph_params.flags (SPH_DFSPH_CORRECTED_GRADIENT) */
  float tension_ratio;  /* sph_world_params.tension_ratio; REST_SPHERE_TENSION overrides it (a
                           measurement switch) */
  uint32_t features;    /* sph_world_def.features */
} sphere_case;

static void run_sphere(const sphere_case* sc) {
  const float spacing = 0.02f;
  const float radius = (validation_full() ? 14.0f : 6.0f) * spacing;
  const double disturbance = sc->disturbance;
  support_world w;
  sph_world* world;
  sph_world_def def;
  sph_world_params params;
  support_sphere ball = {{0.0, 0.0, 0.0}, 0.0, 0.0, 0.0, NULL, 12345, 0};
  float mass = 0.0f, h, rest;
  float* lattice = NULL;
  uint32_t n;
  double ke0, gyration0 = 0.0, ke[FRAMES], worst_mean = 0.0, worst_particle = 0.0, worst_radius = 0.0;
  double max_first = 0.0, max_last = 0.0, end_speed = 0.0;

  sph_world_def_init(&def);
  def.particle_spacing = spacing;
  def.capacity = 0; /* the ball's particles */
  def.solver = sc->solver;
  def.features = sc->features;
  /* A measurement switch: the Shepard-normalised density, whose surface particles read about rho0
   * instead of a kernel's missing share below it (docs/validation.md, session 21). */
  if (getenv("REST_SPHERE_NORMALIZED") && atoi(getenv("REST_SPHERE_NORMALIZED")))
    def.features |= SPH_FEATURE_NORMALIZED_DENSITY;
  EXPECT_OK(support_params_gravity_and_steps(&params, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-3f));
  params.tension_ratio =
      getenv("REST_SPHERE_TENSION") ? (float)atof(getenv("REST_SPHERE_TENSION")) : sc->tension_ratio;
  if (params.tension_ratio != 0.0f) printf("tension_ratio %g\n", (double)params.tension_ratio);
  ball.radius = radius;
  ball.speed = disturbance;
  EXPECT_OK(support_rest_sphere_open(&w, sph_test_backend(), &def, &params, &ball, &n));
  world = w.world;
  if (sc->dfsph_flags) {
    sph_dfsph_params dp;
    sph_dfsph_params_init(&dp);
    EXPECT_OK(sph_world_get_dfsph_params(world, &dp));
    dp.flags = sc->dfsph_flags;
    EXPECT_OK(sph_world_set_dfsph_params(world, &dp));
  }
  h = w.def.kernel_radius;
  rest = w.def.rest_density;
  mass = w.mass;
  EXPECT_OK(support_kinetic_energy(world, mass, &ke0));
  {
    uint32_t count = 0;
    double c[3] = {0.0, 0.0, 0.0};
    /* the lattice as spawned */
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)&lattice, &count));
    for (uint32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) c[k] += lattice[3 * i + k] / (double)n;
    for (uint32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) gyration0 += (lattice[3 * i + k] - c[k]) * (lattice[3 * i + k] - c[k]) / n;
    gyration0 = sqrt(gyration0);
  }
  free(lattice);

  for (int f = 0; f < FRAMES; ++f) {
    float* x = NULL;
    float* rho = NULL;
    double c[3] = {0.0, 0.0, 0.0}, density_sum = 0.0, gyration = 0.0, worst = 0.0;
    uint32_t interior = 0;
    uint32_t count = 0;
    EXPECT_OK(sph_world_step(world, 1.0f / 25.0f));
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)&x, &count));
    assert_int_equal(count, n);
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, &count));
    for (uint32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) c[k] += x[3 * i + k] / (double)n;
    for (uint32_t i = 0; i < n; ++i) {
      const double dx = x[3 * i] - c[0], dy = x[3 * i + 1] - c[1], dz = x[3 * i + 2] - c[2];
      const double r2 = dx * dx + dy * dy + dz * dz;
      gyration += r2 / n;
      if (sqrt(r2) < radius - 2.0 * h) {
        const double e = fabs(rho[i] - rest) / rest;
        density_sum += rho[i];
        if (e > worst) worst = e;
        ++interior;
      }
    }
    gyration = sqrt(gyration);
    assert_true(interior >= 50);
    EXPECT_OK(support_kinetic_energy(world, mass, &ke[f]));
    {
      const double mean_error = fabs(density_sum / interior - rest) / rest;
      const double radius_change = fabs(gyration / gyration0 - 1.0);
      if (mean_error > worst_mean) worst_mean = mean_error;
      if (worst > worst_particle) worst_particle = worst;
      if (radius_change > worst_radius) worst_radius = radius_change;
      if (f % 10 == 9)
        printf(
            "frame %3d: interior mean density %.2f (%.3f %% off), worst particle %.3f %%, radius of gyration "
            "%+.3f "
            "%%, KE %.3g J\n",
            f + 1, density_sum / interior, 100.0 * mean_error, 100.0 * worst,
            100.0 * (gyration / gyration0 - 1.0), ke[f]);
    }
    free(x);
    free(rho);
  }
  {
    float* v = NULL;
    uint32_t count = 0;
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &count));
    for (uint32_t i = 0; i < n; ++i) {
      const double s2 = (double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
                        (double)v[3 * i + 2] * v[3 * i + 2];
      if (s2 > end_speed * end_speed) end_speed = sqrt(s2);
    }
    free(v);
  }
  for (int f = 0; f < FRAMES; ++f) {
    if (f < FRAMES / 2 && ke[f] > max_first) max_first = ke[f];
    if (f >= FRAMES / 2 && ke[f] > max_last) max_last = ke[f];
  }
  printf(
      "%s: %u particles (radius %.2f m, h = %.4f m): worst interior mean density error %.3f %% (bound 1 %%), "
      "worst "
      "particle %.3f %% (bound 2 %%), worst radius change %.3f %% (bound 2 %%); KE %.3g J at the start, "
      "peaks "
      "%.3g / %.3g J (frames 1-50 / 51-100), %.3g J at the end; fastest particle at the end %.3g m/s\n",
      sc->name, n, radius, h, 100.0 * worst_mean, 100.0 * worst_particle, 100.0 * worst_radius, ke0,
      max_first, max_last, ke[FRAMES - 1], end_speed);
  {
    char file[64];
    FILE* out;
    snprintf(file, sizeof file, "rest_sphere_%s.txt", sc->name);
    out = validation_open_output(file);
    if (out) {
      fprintf(out, "%u %.4f %.4f %.4f %.4g %.4g\n", n, 100.0 * worst_mean, 100.0 * worst_particle,
              100.0 * worst_radius, ke0, ke[FRAMES - 1]);
      fclose(out);
    }
  }
  if (sc->check_density) {
    assert_true(worst_mean <= 0.01);
    assert_true(worst_particle <= 0.02);
  }
  if (sc->check_density && sc->tension_ratio > 0.0f) {
    /* A fluid that pulls as it pushes answers a 1 mm/s disturbance with acoustic density
     * fluctuations, about v / c = 1e-4 of rho0 (c = 10 m/s); 0.1 % is ten times that, and below the
     * normalised density's own 0.43 % without a tension (a fluid that only pushes swells). */
    assert_true(worst_mean <= 0.001);
    assert_true(worst_particle <= 0.001);
  }
  assert_true(worst_radius <= 0.02);
  if (disturbance > 0.0) {
    /* Decaying: below the start, and the second half's peak below the first half's. */
    assert_true(ke[FRAMES - 1] < ke0);
    assert_true(max_last <= max_first);
  } else {
    /* At rest it stays at rest: the only motion is float round-off of the density sums (about
     * 1e-7 of rho0, i.e. 1e-5 m/s of pressure-driven speed at c = 10 m/s). 1 mm/s, a
     * thousandth of the benchmark's disturbance of the moving run, catches a surface that
     * sheds particles or a force bias, which reach metres per second. */
    assert_true(end_speed <= 1e-3);
    /* and the round-off motion, like a disturbance, is damped: no instability grows. */
    assert_true(max_last <= max_first);
  }
  EXPECT_OK(support_world_close(&w));
}

static void test_rest(void** state) {
  const sphere_case sc = {"rest", 0.0, 1, SPH_SOLVER_WCSPH, 0u, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

static void test_disturbed(void** state) {
  const sphere_case sc = {"disturbed", 1e-3, 0, SPH_SOLVER_WCSPH, 0u, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

static void test_disturbed_density(void** state) {
  const sphere_case sc = {"disturbed_density", 1e-3, 1, SPH_SOLVER_WCSPH, 0u, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

/* The known issue's run with a bounded tension (sph_world_params.tension_ratio, 0.005) and the
 * normalised density, whose free surface reads about rho0: the interior stays at rho0 (measured
 * 0.000 % mean, 0.001 % worst; docs/validation.md, "Session 21: a bounded tension"). With the plain
 * summation density a tension cannot be used here: every surface particle sits far below the
 * floor and takes the whole tension, and the ball sheds even at rest (tau 0.0005: radius +1.7 %). */
static void test_disturbed_tension(void** state) {
  const sphere_case sc = {"disturbed_tension",           1e-3, 1, SPH_SOLVER_WCSPH, 0u, 0.005f,
                          SPH_FEATURE_NORMALIZED_DENSITY};
  (void)state;
  run_sphere(&sc);
}

/* DFSPH (issue 16 item 4): the same sphere and bounds with the incompressible solver. */
static void test_dfsph_rest(void** state) {
  const sphere_case sc = {"dfsph_rest", 0.0, 1, SPH_SOLVER_DFSPH, 0u, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

/* The same with DFSPH's corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT). */
static void test_dfsph_rest_corrected(void** state) {
  const sphere_case sc = {"dfsph_rest_corrected",       0.0,  1, SPH_SOLVER_DFSPH,
                          SPH_DFSPH_CORRECTED_GRADIENT, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

static void test_dfsph_disturbed(void** state) {
  const sphere_case sc = {"dfsph_disturbed", 1e-3, 1, SPH_SOLVER_DFSPH, 0u, 0.0f, 0u};
  (void)state;
  run_sphere(&sc);
}

/* argv[1] picks one run (rest | disturbed | disturbed_density | disturbed_tension | dfsph_rest |
 * dfsph_rest_corrected |
 * dfsph_disturbed);
 * none runs rest and disturbed. */
int main(int argc, char** argv) {
  const struct CMUnitTest rest[] = {cmocka_unit_test(test_rest)};
  const struct CMUnitTest disturbed[] = {cmocka_unit_test(test_disturbed)};
  const struct CMUnitTest disturbed_density[] = {cmocka_unit_test(test_disturbed_density)};
  const struct CMUnitTest disturbed_tension[] = {cmocka_unit_test(test_disturbed_tension)};
  const struct CMUnitTest dfsph_rest[] = {cmocka_unit_test(test_dfsph_rest)};
  const struct CMUnitTest dfsph_disturbed[] = {cmocka_unit_test(test_dfsph_disturbed)};
  const struct CMUnitTest dfsph_rest_corrected[] = {cmocka_unit_test(test_dfsph_rest_corrected)};
  int failed = 0, ran = 0;
  if (argc >= 2 && strcmp(argv[1], "dfsph_rest_corrected") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_dfsph_corrected", dfsph_rest_corrected, NULL, NULL);
    ++ran;
  }
  if (argc >= 2 && strcmp(argv[1], "dfsph_rest") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_dfsph", dfsph_rest, NULL, NULL);
    ++ran;
  }
  if (argc >= 2 && strcmp(argv[1], "dfsph_disturbed") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_dfsph_disturbed", dfsph_disturbed, NULL, NULL);
    ++ran;
  }
  if (argc < 2 || strcmp(argv[1], "rest") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere", rest, NULL, NULL);
    ++ran;
  }
  if (argc < 2 || strcmp(argv[1], "disturbed") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_disturbed", disturbed, NULL, NULL);
    ++ran;
  }
  if (argc >= 2 && strcmp(argv[1], "disturbed_tension") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_disturbed_tension", disturbed_tension, NULL, NULL);
    ++ran;
  }
  if (argc >= 2 && strcmp(argv[1], "disturbed_density") == 0) {
    failed += cmocka_run_group_tests_name("rest_sphere_disturbed_density", disturbed_density, NULL, NULL);
    ++ran;
  }
  if (ran == 0) { /* a name that is no case: an error, not a run of none that passes */
    fprintf(stderr, "validation_rest_sphere: no case named '%s'\n", argv[1]);
    return 2;
  }
  return failed;
}
