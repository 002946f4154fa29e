// SPDX-License-Identifier: MIT
/* Closed box: the total energy of water sloshing in a closed tank never grows by more than
 * 0.5 %, and, without gravity, momentum drifts only at float round-off.
 *
 * Energy counted: kinetic (sum m v^2 / 2) + gravitational potential (sum m g y, y from the
 * floor) + the equation of state's internal energy, sum m e(rho_i) with de/drho = p / rho^2:
 * for the ideal gas clamped at zero below rho0, e(rho) = k (ln(rho / rho0) + rho0 / rho - 1)
 * above rho0 and 0 below. That is the energy the pressure force exchanges with the motion
 * (with summation density and the p / rho^2 pressure form over the same kernel, W_spiky in both
 * since the density follows the force, the exchange is exact in time; with the thesis's W_poly6
 * density against the W_spiky force this box gained 18 %, 58 % at the full resolution:
 * docs/validation.md, "Closed box"), so
 * leaving it out would make a compressed column look as if it lost energy. Viscosity and
 * the inelastic wall contacts (restitution 0) only remove energy; what the test catches is
 * energy made by the integrator, an unstable step or a collision that throws a particle.
 * 0.5 % (the issue's) of the start's total is about a third of the compression energy the
 * column stores at rest, so any real source of energy shows.
 *
 * Momentum: a ball of water with random internal motion and zero mean, in the middle of the
 * same box, without gravity, for a time in which no particle reaches a wall (checked): the
 * pair forces are antisymmetric, so the total momentum stays at round-off, against the
 * scale sum |m v|. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "validation_util.h"

#define GRAVITY 9.81
/* SPH_DFSPH_CORRECTED_GRADIENT's momentum drift over the 0.5 s run: measured 5.7e-4 of sum |m v|
 * (session 16; 1.9e-8 without it); 2e-3 leaves a factor of 3.5 and still catches a correction
 * gone wrong (a wrong L or sign moves the ball by percents). */
#define MOMENTUM_BOUND 2e-3

static double internal_energy(double k, double rho0, double rho) {
  if (rho <= rho0) return 0.0;
  return k * (log(rho / rho0) + rho0 / rho - 1.0);
}

static double total_energy(const sph_world* world, float mass, double k, double rho0, double* kinetic) {
  float* v = NULL;
  float* x = NULL;
  float* rho = NULL;
  double e_kin = 0.0, e_pot = 0.0, e_int = 0.0;
  uint32_t n = 0;
  EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &n));
  EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)&x, &n));
  EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, &n));
  for (uint32_t i = 0; i < n; ++i) {
    e_kin += 0.5 * mass *
             ((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
              (double)v[3 * i + 2] * v[3 * i + 2]);
    e_pot += mass * GRAVITY * x[3 * i + 1];
    e_int += mass * internal_energy(k, rho0, rho[i]);
  }
  free(v);
  free(x);
  free(rho);
  *kinetic = e_kin;
  return e_kin + e_pot + e_int;
}

/* solver: the weakly compressible scheme (its ideal gas's internal energy counted) or DFSPH. DFSPH
 * has no equation of state: its projections hold the density at rho0 within the solve's bound
 * (0.1 %) and store no energy, so its total is kinetic + potential, and a projection can only
 * remove kinetic energy (it makes the velocities' closest divergence-free field); what the bound
 * catches is a solve or a wall contact that adds energy. */
/* SPH_DFSPH_JACOBI, SPH_DFSPH_CONJUGATE_GRADIENTS or SPH_DFSPH_CHEBYSHEV for the DFSPH runs (0: the
 * default). */
static uint32_t dfsph_linear_solver = 0;
/* sph_dfsph_params.flags for the DFSPH runs (SPH_DFSPH_CORRECTED_GRADIENT: the `_corrected` cases). */
static uint32_t dfsph_flags = 0;

static void set_dfsph(sph_world* world) {
  sph_dfsph_params dfsph;
  EXPECT_OK(sph_dfsph_params_init(&dfsph));
  EXPECT_OK(sph_world_get_dfsph_params(world, &dfsph));
  if (dfsph_linear_solver != 0) dfsph.linear_solver = dfsph_linear_solver;
  dfsph.flags = dfsph_flags;
  EXPECT_OK(sph_world_set_dfsph_params(world, &dfsph));
}

static void run_energy_never_grows(sph_solver solver) {
  const int full = validation_full();
  const double step = full ? 0.005 : 0.01;
  const uint32_t across = full ? 24 : 12;
  const uint32_t lattice[3] = {across, 2 * across, across / 2};
  const double origin[3] = {0.0, 0.0, 0.0};
  const double box_min[3] = {0.0, 0.0, 0.0};
  const double box_max[3] = {4.0 * across * step, 3.0 * across * step, 0.5 * across * step};
  support_world w;
  sph_world* world;
  sph_world_def def;
  sph_world_params params;
  sph_sdf* sdf = NULL;
  float* points = NULL;
  float mass = 0.0f;
  double e0, worst = -1e30, kinetic, peak_kinetic = 0.0, e_end = 0.0;
  const int frames = 60; /* 1.2 s: the column collapses, hits the far wall and sloshes back */
  uint32_t n = 0;
  double stiffness;

  EXPECT_OK(support_fcc_box(lattice, step, origin, &points, &n));
  sph_world_def_init(&def);
  def.capacity = n;
  def.particle_spacing = (float)(step * sqrt(2.0));
  def.solver = solver;
  sph_world_params_init(&params);
  if (solver != SPH_SOLVER_DFSPH) params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  params.viscosity = 0.05f;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, &params));
  world = w.world;
  def = w.def;
  if (solver == SPH_SOLVER_DFSPH) set_dfsph(world);
  EXPECT_OK(support_tank_between(w.context, world, box_min, box_max, 0.5 * step, 0.0f, &sdf, NULL));
  EXPECT_OK(support_spawn(world, points, NULL, n));
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  free(points);
  stiffness = solver == SPH_SOLVER_DFSPH ? 0.0 : params.stiffness; /* no internal energy in DFSPH */
  e0 = total_energy(world, mass, stiffness, def.rest_density, &kinetic);
  for (int f = 0; f < frames; ++f) {
    double e;
    EXPECT_OK(sph_world_step(world, 0.02f));
    e = total_energy(world, mass, stiffness, def.rest_density, &kinetic);
    if (kinetic > peak_kinetic) peak_kinetic = kinetic;
    if ((e - e0) / e0 > worst) worst = (e - e0) / e0;
    if (f % 10 == 9)
      printf("t = %.2f s: total energy %+.3f %% of the start, kinetic %.3g J\n", 0.02 * (f + 1),
             100.0 * (e - e0) / e0, kinetic);
    e_end = e;
  }
  printf(
      "%u particles: E0 = %.4g J; largest growth %+.3f %% (bound +0.5 %%); at the end %+.2f %%; peak kinetic "
      "%.3g J "
      "(%.1f %% of E0)\n",
      n, e0, 100.0 * worst, 100.0 * (e_end - e0) / e0, peak_kinetic, 100.0 * peak_kinetic / e0);
  {
    FILE* out = validation_open_output(solver != SPH_SOLVER_DFSPH ? "closed_box_energy.txt"
                                       : dfsph_flags              ? "closed_box_energy_dfsph_corrected.txt"
                                       : dfsph_linear_solver == SPH_DFSPH_CHEBYSHEV
                                           ? "closed_box_energy_dfsph_chebyshev.txt"
                                           : "closed_box_energy_dfsph.txt");
    if (out) {
      fprintf(out, "%u %.4f %.4f %.4f\n", n, 100.0 * worst, 100.0 * (e_end - e0) / e0,
              100.0 * peak_kinetic / e0);
      fclose(out);
    }
  }
  /* The water really moved: a good share of the potential energy went through kinetic. */
  assert_true(peak_kinetic > 0.05 * e0);
  assert_true(worst <= 0.005);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

static void test_energy_never_grows(void** state) {
  (void)state;
  run_energy_never_grows(SPH_SOLVER_WCSPH);
}

static void test_energy_never_grows_dfsph(void** state) {
  (void)state;
  run_energy_never_grows(SPH_SOLVER_DFSPH);
}

static void run_momentum(sph_solver solver, double bound) {
  const float spacing = 0.02f;
  const float radius = (validation_full() ? 10.0f : 5.0f) * spacing;
  const double box = 1.0; /* the ball sits in the middle of a 1 m box */
  const double box_min[3] = {0.0, 0.0, 0.0};
  const double box_max[3] = {box, box, box};
  support_world w;
  sph_world* world;
  sph_world_def def;
  sph_sdf* sdf = NULL;
  float* points = NULL;
  float* v0;
  float mass = 0.0f;
  uint64_t rng = 0x2545f4914f6cdd1dull;
  double mean[3] = {0.0, 0.0, 0.0}, p[3] = {0.0, 0.0, 0.0}, scale = 0.0, nearest_wall = 1e30;
  uint32_t n = 0;

  EXPECT_OK(support_fcc_sphere(NULL, radius, spacing, &points, &n));
  v0 = (float*)malloc(sizeof(float) * 3 * n);
  assert_non_null(v0);
  for (uint32_t i = 0; i < n; ++i) {
    points[3 * i] += (float)(0.5 * box);
    points[3 * i + 1] += (float)(0.5 * box);
    points[3 * i + 2] += (float)(0.5 * box);
    for (int k = 0; k < 3; ++k) {
      v0[3 * i + k] = (float)(0.2 * (support_random(&rng) - 0.5));
      mean[k] += v0[3 * i + k] / n;
    }
  }
  for (uint32_t i = 0; i < 3 * n; ++i) v0[i] -= (float)mean[i % 3]; /* zero total momentum */
  sph_world_def_init(&def);
  def.capacity = n;
  def.particle_spacing = spacing;
  def.solver = solver;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  world = w.world;
  if (solver == SPH_SOLVER_DFSPH) set_dfsph(world);
  EXPECT_OK(support_set_gravity_and_steps(world, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-3f));
  EXPECT_OK(support_tank_between(w.context, world, box_min, box_max, 0.02, 0.0f, &sdf, NULL));
  EXPECT_OK(support_spawn(world, points, v0, n));
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  for (uint32_t i = 0; i < 3 * n; ++i) scale += mass * fabs((double)v0[i]);
  free(points);
  free(v0);
  for (int f = 0; f < 10; ++f) EXPECT_OK(sph_world_step(world, 0.05f));
  {
    float* v = NULL;
    float* x = NULL;
    uint32_t count = 0;
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &count));
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)&x, &count));
    for (uint32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const double wall = fmin(x[3 * i + k], box - x[3 * i + k]);
        p[k] += mass * (double)v[3 * i + k];
        if (wall < nearest_wall) nearest_wall = wall;
      }
    free(v);
    free(x);
  }
  {
    const double drift = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    printf(
        "%s, %u particles, 0.5 s without gravity: |P| = %.3g kg m/s against sum |m v| = %.3g (%.2e, bound "
        "%.0e); nearest wall %.3f m\n",
        solver == SPH_SOLVER_DFSPH ? (dfsph_flags ? "DFSPH, corrected gradient" : "DFSPH") : "WCSPH", n,
        drift, scale, drift / scale, bound, nearest_wall);
    {
      FILE* out = validation_open_output(solver != SPH_SOLVER_DFSPH ? "closed_box_momentum.txt"
                                         : dfsph_flags ? "closed_box_momentum_dfsph_corrected.txt"
                                                       : "closed_box_momentum_dfsph.txt");
      if (out) {
        fprintf(out, "%u %.3e\n", n, drift / scale);
        fclose(out);
      }
    }
    /* No wall touched, so the walls exchanged no momentum. */
    assert_true(nearest_wall > 0.0);
    /* Round-off: each velocity update rounds at ~6e-8 of |v|, randomly in sign; over ~500
     * substeps the sum walks to ~sqrt(500 N) 6e-8 |v| ~ 1e-6 of sum |m v|. 1e-5 leaves a factor
     * of ten and catches any asymmetric pair term (percents). */
    assert_true(drift <= bound * scale);
  }
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

static void test_momentum_round_off(void** state) {
  (void)state;
  run_momentum(SPH_SOLVER_WCSPH, 1e-5);
}

/* DFSPH's pair terms are antisymmetric as well (the velocity update's m (k_i + k_j) grad W_ij): the
 * same round-off bound. */
static void test_momentum_round_off_dfsph(void** state) {
  (void)state;
  run_momentum(SPH_SOLVER_DFSPH, 1e-5);
}

/* With SPH_DFSPH_CORRECTED_GRADIENT the pair terms are not antisymmetric (L_i grad W_ij against
 * L_j grad W_ji; physics/dfsph_gradient_correction.h): the drift measured and bounded (MOMENTUM_BOUND). */
static void test_momentum_dfsph_corrected(void** state) {
  (void)state;
  run_momentum(SPH_SOLVER_DFSPH, MOMENTUM_BOUND);
}

/* argv[1] picks one check (energy | energy_dfsph | energy_dfsph_cg | energy_dfsph_chebyshev |
 * energy_dfsph_corrected | momentum | momentum_dfsph | momentum_dfsph_corrected); none runs energy and
 * momentum. energy_dfsph_cg: DFSPH's density solve by conjugate gradients (the solve that may
 * lower a particle's pressure within a substep, so the check that it adds no energy);
 * energy_dfsph_chebyshev: its Chebyshev solve, whose accelerated steps overshoot and whose release
 * takes pressure back (without the release this case gained 39 times its energy once settled). */
int main(int argc, char** argv) {
  const struct CMUnitTest energy[] = {cmocka_unit_test(test_energy_never_grows)};
  const struct CMUnitTest energy_dfsph[] = {cmocka_unit_test(test_energy_never_grows_dfsph)};
  const struct CMUnitTest momentum[] = {cmocka_unit_test(test_momentum_round_off)};
  int failed = 0;
  if (argc >= 2 && strcmp(argv[1], "energy_dfsph_cg") == 0) {
    dfsph_linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
    return cmocka_run_group_tests_name("closed_box_energy_dfsph_cg", energy_dfsph, NULL, NULL);
  }
  if (argc >= 2 && strcmp(argv[1], "energy_dfsph_chebyshev") == 0) {
    dfsph_linear_solver = SPH_DFSPH_CHEBYSHEV;
    return cmocka_run_group_tests_name("closed_box_energy_dfsph_chebyshev", energy_dfsph, NULL, NULL);
  }
  if (argc >= 2 && strcmp(argv[1], "energy_dfsph") == 0)
    return cmocka_run_group_tests_name("closed_box_energy_dfsph", energy_dfsph, NULL, NULL);
  if (argc >= 2 && strcmp(argv[1], "energy_dfsph_corrected") == 0) {
    dfsph_flags = SPH_DFSPH_CORRECTED_GRADIENT;
    return cmocka_run_group_tests_name("closed_box_energy_dfsph_corrected", energy_dfsph, NULL, NULL);
  }
  if (argc >= 2 && strcmp(argv[1], "momentum_dfsph") == 0) {
    const struct CMUnitTest t[] = {cmocka_unit_test(test_momentum_round_off_dfsph)};
    return cmocka_run_group_tests_name("closed_box_momentum_dfsph", t, NULL, NULL);
  }
  if (argc >= 2 && strcmp(argv[1], "momentum_dfsph_corrected") == 0) {
    const struct CMUnitTest t[] = {cmocka_unit_test(test_momentum_dfsph_corrected)};
    dfsph_flags = SPH_DFSPH_CORRECTED_GRADIENT;
    return cmocka_run_group_tests_name("closed_box_momentum_dfsph_corrected", t, NULL, NULL);
  }
  if (argc >= 2 && strcmp(argv[1], "energy") != 0 && strcmp(argv[1], "momentum") != 0) {
    /* a name that is no case: an error, not a run of none that passes */
    fprintf(stderr, "validation_closed_box: no case named '%s'\n", argv[1]);
    return 2;
  }
  if (argc < 2 || strcmp(argv[1], "energy") == 0)
    failed += cmocka_run_group_tests_name("closed_box_energy", energy, NULL, NULL);
  if (argc < 2 || strcmp(argv[1], "momentum") == 0)
    failed += cmocka_run_group_tests_name("closed_box_momentum", momentum, NULL, NULL);
  return failed;
}
