// SPDX-License-Identifier: MIT
/* Dam break against Martin & Moyce (1952): the surge front's mean error <= 8 % and worst point
 * <= 15 % over T in [0.8, 3.3], after at most one fitted time shift |dT| <= 0.2, which the
 * test reports. The case itself (tank, slab, equation of state, front) is dam_break.c; why each
 * choice is what it is, and what was tried, is in docs/validation.md.
 *
 * The bounds are the issue's. They are wide for a reason: the measurements scatter by several
 * percent between repeats, the gate of the experiment took time to lift (hence the one time
 * shift), and the simulation has free-slip walls where the experiment had a real floor.
 *
 * CI runs 20 lattice layers across the column (2,400 particles); SPH_VALIDATION_FULL=1 runs 40
 * (9,600). SPH_VALIDATION_OUT receives the front history and the comparison. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dam_break.h"
#include "validation_util.h"

static void trace_line(void* user, double T, double Z) {
  if (user) fprintf((FILE*)user, "%.4f,%.4f\n", T, Z);
}

/* The features the weakly compressible case adds (argv[1] = diffusion: the normalised density
 * with the density diffusion, SPH_FEATURE_DENSITY_DIFFUSION, under the same bounds). */
static uint32_t wcsph_features = 0;

static void test_dam_break(void** state) {
  sph_context* context = NULL;
  dam_break_config config;
  dam_break_result* result = (dam_break_result*)malloc(sizeof(dam_break_result));
  FILE* trace =
      validation_open_output(wcsph_features ? "dam_break_diffusion_front.csv" : "dam_break_front.csv");
  sph_result r;
  (void)state;
  assert_non_null(result);
  EXPECT_OK(sph_test_context_create(&context));
  dam_break_config_default(&config, validation_full() ? 40 : 20);
  config.features = wcsph_features;
  if (trace) fprintf(trace, "T,Z\n");
  r = dam_break_run(context, &config, result, trace_line, trace);
  if (trace) fclose(trace);
  if (r != SPH_OK) printf("dam break failed: %s: %s\n", sph_result_string(r), result->message);
  assert_int_equal(r, SPH_OK);
  printf(
      "dam break%s: %u lattice layers across the column, %u particles, spacing %.2f mm, c = %.1f m/s, mu = "
      "%.3f Pa s, "
      "%llu substeps, %.2f s wall for %.3f s simulated\n",
      wcsph_features ? " (density diffusion)" : "", config.layers_across, result->particles,
      1e3 * result->spacing, config.speed_of_sound, config.viscosity, (unsigned long long)result->substeps,
      result->wall_seconds, result->simulated_seconds);
  printf(
      "  fitted time shift dT = %+.3f (bound |dT| <= %.1f): mean error %.2f %% (bound 8 %%), worst %.2f %% "
      "(bound 15 "
      "%%) over %u points; without the shift %.2f %% / %.2f %%\n",
      result->shift_T, DAM_BREAK_MAX_SHIFT, 100.0 * result->mean_error, 100.0 * result->max_error,
      result->compared, 100.0 * result->mean_error_unshifted, 100.0 * result->max_error_unshifted);
  printf(
      "  mean compression of the particles above rest density %.2f %%, largest %.2f %%; %u particles outside "
      "the "
      "tank\n",
      100.0 * result->mean_compression, 100.0 * result->max_compression, result->escaped);
  printf("  %-6s %-8s %-8s %s\n", "T", "Z meas.", "Z SPH", "error");
  for (int m = 0; m < DAM_BREAK_MEASUREMENTS; ++m) {
    const double T = dam_break_measured_T[m] + result->shift_T;
    uint32_t i = 1;
    double w;
    if (dam_break_measured_T[m] < DAM_BREAK_T_FIRST || dam_break_measured_T[m] > DAM_BREAK_T_LAST) continue;
    while (i < result->samples - 1 && result->T[i] < T) ++i;
    w = (T - result->T[i - 1]) / (result->T[i] - result->T[i - 1]);
    {
      const double Z = result->Z[i - 1] + w * (result->Z[i] - result->Z[i - 1]);
      printf("  %-6.2f %-8.2f %-8.3f %+.1f %%\n", dam_break_measured_T[m], dam_break_measured_Z[m], Z,
             100.0 * (Z / dam_break_measured_Z[m] - 1.0));
    }
  }
  {
    FILE* out = validation_open_output(wcsph_features ? "dam_break_diffusion.txt" : "dam_break.txt");
    if (out) {
      fprintf(out, "%u %u %.4f %.3f %.3f %.3f %.3f %.3f %u\n", config.layers_across, result->particles,
              result->shift_T, 100.0 * result->mean_error, 100.0 * result->max_error,
              100.0 * result->mean_error_unshifted, 100.0 * result->max_error_unshifted,
              100.0 * result->mean_compression, result->escaped);
      fclose(out);
    }
  }
  assert_true(result->compared >= 10);
  assert_true(fabs(result->shift_T) <= DAM_BREAK_MAX_SHIFT + 1e-9);
  assert_true(result->mean_error <= 0.08);
  assert_true(result->max_error <= 0.15);
  /* The tank is closed: every particle is still inside it (to half a lattice step). */
  assert_int_equal(result->escaped, 0);
  free(result);
  EXPECT_OK(sph_context_destroy(context));
}

/* DFSPH (issue 16 item 4) on the same case, at the same resolution (20 layers in CI, 40 full):
 * - the front's mean error <= 5 % (the bound for the incompressible solver: it has no
 *   speed of sound to slow the collapse) and worst <= 15 %, at most one fitted shift as above;
 * - every substep's density solve reached the user's bound (the default 0.1 %): its achieved
 *   mean error, sph_stats.density_error_max over the run, is at most the bound, and no solve
 *   stopped at its cap (none reported in sph_stats or by an event);
 * - every substep's largest particle error (sph_stats.density_error_largest over the run) is
 *   within density_error_max (the default 5 %), with no tolerance: the solve stops only once it
 *   is, or at its cap, which the case asserts never happens (the conjugate gradients ran to their
 *   cap in 4 solves before their restart looked at the largest error; docs/validation.md);
 * - the tank is closed: nothing escapes.
 * `boundary` adds SPH_FEATURE_BOUNDARY_DENSITY (the walls in the density and in the solves);
 * dam_break.c then stands the walls spacing/2 beyond the lattice's outer layers, where the
 * boundary calibration puts a resting first layer. Measured at 20 layers: mean 1.86 %, worst
 * 4.92 % at dT = -0.200, the shift's bound (unshifted 10.5 % / 17.9 %): the front runs early, as
 * the floor's particles along the slab's side walls start over-read (the edges' +25 %,
 * docs/physics.md, "Walls in the density") and are pushed out at once. */
/* SPH_DFSPH_JACOBI, SPH_DFSPH_CONJUGATE_GRADIENTS or SPH_DFSPH_CHEBYSHEV for the DFSPH cases (0: the
 * default); the _cg and _chebyshev cases hold those solves to the same bounds. */
static uint32_t dfsph_linear_solver = 0;
/* sph_dfsph_params.flags for the DFSPH cases (the _corrected cases: SPH_DFSPH_CORRECTED_GRADIENT). */
static uint32_t dfsph_flags = 0;

/* Runs the DFSPH case and asserts its bounds; returns the density solve's iterations over the run. */
static unsigned long long run_dfsph(uint32_t features) {
  sph_context* context = NULL;
  dam_break_config config;
  dam_break_result* result;
  sph_result r;
  result = (dam_break_result*)malloc(sizeof(dam_break_result));
  assert_non_null(result);
  EXPECT_OK(sph_test_context_create(&context));
  dam_break_config_default(&config, validation_full() ? 40 : 20);
  config.solver = SPH_SOLVER_DFSPH;
  config.features = features;
  config.dfsph_linear_solver = dfsph_linear_solver;
  config.dfsph_flags = dfsph_flags;
  r = dam_break_run(context, &config, result, trace_line, getenv("SPH_TRACE") ? stdout : NULL);
  if (r != SPH_OK) printf("dam break failed: %s: %s\n", sph_result_string(r), result->message);
  assert_int_equal(r, SPH_OK);
  printf(
      "DFSPH dam break%s: %u particles, %llu substeps, %.2f s wall for %.3f s simulated; density solve: %llu "
      "iterations (%.2f a substep, max %u), achieved error mean %.4f %% max %.4f %% (bound 0.1 %%), %u "
      "capped "
      "(%u events), %u guarded, largest particle error %.4f %% (bound 5 %%); divergence solve %llu "
      "iterations\n",
      features ? " (boundary density)" : "", result->particles, (unsigned long long)result->substeps,
      result->wall_seconds, result->simulated_seconds, (unsigned long long)result->pressure_iterations,
      (double)result->pressure_iterations / (double)(result->substeps ? result->substeps : 1),
      result->pressure_iterations_max, 100.0 * result->density_error_mean, 100.0 * result->density_error_max,
      result->capped_substeps, result->capped_events, result->guarded_substeps,
      100.0 * result->density_error_largest, (unsigned long long)result->divergence_iterations);
  printf(
      "  fitted shift dT = %+.3f: mean error %.2f %% (bound 5 %%), worst %.2f %% (bound 15 %%) over %u "
      "points; "
      "unshifted %.2f %% / %.2f %%; largest compression %.2f %%; %u outside the tank\n",
      result->shift_T, 100.0 * result->mean_error, 100.0 * result->max_error, result->compared,
      100.0 * result->mean_error_unshifted, 100.0 * result->max_error_unshifted,
      100.0 * result->max_compression, result->escaped);
  /* Reported, not asserted: the solves bound the density their linearised continuity equation
   * predicts for the substep's end; the positions' update adds terms of second order in dt |grad v|
   * and the collision response moves particles after it (measured at these 1.35 ms steps 0.90-1.56
   * times the bound over the seven cases; at the million-particle bench's 0.1 ms steps 1.03 times,
   * docs/validation.md, "Session 32"). */
  printf(
      "  measured at the frames' ends over every particle: mean density error %.4f %% (%.1f %% of them "
      "above rest)\n",
      100.0 * result->mean_density_error, 100.0 * result->above_share);
  {
    FILE* out = validation_open_output(
        dfsph_flags ? (features ? "dam_break_dfsph_boundary_corrected.txt" : "dam_break_dfsph_corrected.txt")
        : features  ? (dfsph_linear_solver == SPH_DFSPH_CHEBYSHEV ? "dam_break_dfsph_boundary_chebyshev.txt"
                                                                  : "dam_break_dfsph_boundary.txt")
        : dfsph_linear_solver == SPH_DFSPH_CHEBYSHEV ? "dam_break_dfsph_chebyshev.txt"
                                                     : "dam_break_dfsph.txt");
    if (out) {
      fprintf(out, "%u %u %.4f %.3f %.3f %.5f %llu %llu\n", config.layers_across, result->particles,
              result->shift_T, 100.0 * result->mean_error, 100.0 * result->max_error,
              100.0 * result->density_error_max, (unsigned long long)result->substeps,
              (unsigned long long)result->pressure_iterations);
      fclose(out);
    }
  }
  assert_true(result->compared >= 10);
  assert_true(fabs(result->shift_T) <= DAM_BREAK_MAX_SHIFT + 1e-9);
  assert_true(result->mean_error <= 0.05);
  assert_true(result->max_error <= 0.15);
  assert_int_equal(result->capped_substeps, 0);
  assert_int_equal(result->capped_events, 0);
  assert_true(result->density_error_max <= 0.001);
  assert_true(result->density_error_largest <= 0.05);
  assert_int_equal(result->escaped, 0);
  /* Only the Chebyshev solve has a guard; at the default kernel radius (1.8 spacings) its weights'
   * assumption holds and the guard must not fire (docs/physics.md, "The guard"): 0 guarded substeps
   * in every one of these cases on the CPU (session 41). */
  assert_int_equal(result->guarded_substeps, 0);
  {
    const unsigned long long iterations = result->pressure_iterations;
    free(result);
    EXPECT_OK(sph_context_destroy(context));
    return iterations;
  }
}

static void test_dfsph(void** state) {
  (void)state;
  (void)run_dfsph(0u);
}

/* SPH_DFSPH_CHEBYSHEV (docs/physics.md, DFSPH): the same bounds, and fewer density iterations than
 * the plain Jacobi solve takes on the same case: at most 3/4 of them (measured at 20 layers, CPU,
 * session 29 (rho 0.9): 346 against 652, 0.53 (session 28's rho 0.95: 316, 0.48); the bound fails where the
 * acceleration does nothing, 1.0, and leaves room for the case's own changes). */
static void test_dfsph_chebyshev(void** state) {
  unsigned long long chebyshev, jacobi;
  (void)state;
  dfsph_linear_solver = SPH_DFSPH_CHEBYSHEV;
  chebyshev = run_dfsph(0u);
  dfsph_linear_solver = SPH_DFSPH_JACOBI;
  jacobi = run_dfsph(0u);
  printf("density solve iterations: Chebyshev %llu, Jacobi %llu (%.2f of them; bound 0.75)\n", chebyshev,
         jacobi, (double)chebyshev / (double)(jacobi ? jacobi : 1));
  assert_true((double)chebyshev <= 0.75 * (double)jacobi);
}

static void test_dfsph_boundary(void** state) {
  (void)state;
  (void)run_dfsph(SPH_FEATURE_BOUNDARY_DENSITY);
}

/* Runs `config` in a context of the test's backend and asserts that the run succeeded; the result
 * is the caller's to free. */
static dam_break_result* run_case(const dam_break_config* config) {
  sph_context* context = NULL;
  dam_break_result* result = (dam_break_result*)malloc(sizeof(dam_break_result));
  sph_result r;
  assert_non_null(result);
  EXPECT_OK(sph_test_context_create(&context));
  r = dam_break_run(context, config, result, NULL, NULL);
  if (r != SPH_OK) printf("dam break failed: %s: %s\n", sph_result_string(r), result->message);
  assert_int_equal(r, SPH_OK);
  EXPECT_OK(sph_context_destroy(context));
  return result;
}

/* A density solve held to 2 iterations against a bound of 1e-6 cannot converge in the first
 * frames of the collapse: every such substep must be reported, in sph_stats and as an
 * SPH_EVENT_PRESSURE_SOLVE_CAPPED event (never silently), and the run must go on. */
static void test_dfsph_capped(void** state) {
  dam_break_config config;
  dam_break_result* result;
  (void)state;
  dam_break_config_default(&config, 10);
  config.solver = SPH_SOLVER_DFSPH;
  config.density_error = 1e-6f;
  config.max_iterations = 2;
  config.end_T = 0.5;
  result = run_case(&config);
  printf(
      "capped DFSPH: %llu substeps, %u capped in sph_stats, %u in events, max iterations %u, error max %.4f "
      "%%\n",
      (unsigned long long)result->substeps, result->capped_substeps, result->capped_events,
      result->pressure_iterations_max, 100.0 * result->density_error_max);
  assert_true(result->capped_substeps > 0);
  assert_int_equal(result->capped_events, result->capped_substeps);
  assert_true(result->pressure_iterations_max <= 2);
  assert_true(result->density_error_max > 1e-6);
  free(result);
}

/* SPH_DFSPH_CHEBYSHEV's guard (dfsph_chebyshev.h, DfsphChebyshevGuard): a kernel radius of 3 particle
 * spacings, whose larger neighbourhoods the weights' assumed spectral radius (0.9) does not hold for.
 * Without the guard the accelerated solve's error grew about 3 times an iteration and the second
 * substep failed with non-finite densities (session 40, CPU; kernel radii of 2.2 and 2.6 spacings
 * failed alike in larger dam breaks, docs/validation.md); with it the solve falls back to the plain
 * step and the run goes on: every step succeeds, every density solve ends within its bound (the
 * achieved mean error at most 0.1 %), none is capped, nothing escapes, and the statistics say that
 * the guard fired. 3,072 particles, T up to 1. */
static void test_dfsph_chebyshev_wide_kernel(void** state) {
  dam_break_config config;
  dam_break_result* result;
  (void)state;
  dam_break_config_default(&config, 16);
  config.slab_layers = 12;
  config.kernel_ratio = 3.0f;
  config.solver = SPH_SOLVER_DFSPH;
  config.dfsph_linear_solver = SPH_DFSPH_CHEBYSHEV;
  config.end_T = 1.0;
  config.sample_T = 0.1;
  config.check_reload = 1;
  result = run_case(&config);
  printf(
      "Chebyshev, h = 3 spacings: %u particles, %llu substeps, density solve %llu iterations (max %u), "
      "achieved error max %.4f %% (bound 0.1 %%), %u capped, %u guarded, %u outside the tank\n",
      result->particles, (unsigned long long)result->substeps,
      (unsigned long long)result->pressure_iterations, result->pressure_iterations_max,
      100.0 * result->density_error_max, result->capped_substeps, result->guarded_substeps, result->escaped);
  /* The guard fired and said so (sph_stats.pressure_solves_guarded), and the solves it turned still
   * met their bound. */
  assert_true(result->guarded_substeps > 0);
  assert_true(result->guarded_substeps <= result->substeps);
  /* A checkpoint carries the count (format 13): the world loaded after the guarded frame reports
   * that frame's solver statistics. */
  assert_true(result->reload_checked);
  assert_true(result->reload_stats_equal);
  assert_int_equal(result->capped_substeps, 0);
  assert_int_equal(result->capped_events, 0);
  assert_true(result->density_error_max <= 0.001);
  assert_int_equal(result->escaped, 0);
  free(result);
}

/* argv[1] picks one case (wcsph | diffusion | dfsph | dfsph_boundary | dfsph_capped, dfsph_cg
 * with the conjugate gradients' density solve, dfsph_chebyshev with the Chebyshev solve (against the
 * plain one too), dfsph_boundary_chebyshev (the walls in the density with it), dfsph_corrected and
 * dfsph_boundary_corrected with SPH_DFSPH_CORRECTED_GRADIENT, dfsph_chebyshev_wide_kernel the
 * Chebyshev solve's guard); none runs wcsph. */
int main(int argc, char** argv) {
  const char* which = argc >= 2 ? argv[1] : "wcsph";
  if (strcmp(which, "dfsph_corrected") == 0 || strcmp(which, "dfsph_boundary_corrected") == 0) {
    dfsph_flags = SPH_DFSPH_CORRECTED_GRADIENT;
    which = strcmp(which, "dfsph_corrected") == 0 ? "dfsph" : "dfsph_boundary";
  }
  if (strcmp(which, "dfsph_boundary_chebyshev") == 0) {
    dfsph_linear_solver = SPH_DFSPH_CHEBYSHEV;
    which = "dfsph_boundary";
  }
  if (strcmp(which, "dfsph_cg") == 0) {
    dfsph_linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
    which = "dfsph";
  }
  const struct CMUnitTest wcsph[] = {cmocka_unit_test(test_dam_break)};
  const struct CMUnitTest dfsph[] = {cmocka_unit_test(test_dfsph)};
  const struct CMUnitTest dfsph_boundary[] = {cmocka_unit_test(test_dfsph_boundary)};
  const struct CMUnitTest dfsph_capped[] = {cmocka_unit_test(test_dfsph_capped)};
  const struct CMUnitTest dfsph_chebyshev[] = {cmocka_unit_test(test_dfsph_chebyshev)};
  const struct CMUnitTest dfsph_chebyshev_wide_kernel[] = {
      cmocka_unit_test(test_dfsph_chebyshev_wide_kernel)};
  if (strcmp(which, "dfsph_chebyshev") == 0)
    return cmocka_run_group_tests_name("dam_break_dfsph_chebyshev", dfsph_chebyshev, NULL, NULL);
  if (strcmp(which, "dfsph_chebyshev_wide_kernel") == 0)
    return cmocka_run_group_tests_name("dam_break_dfsph_chebyshev_wide_kernel", dfsph_chebyshev_wide_kernel,
                                       NULL, NULL);
  if (strcmp(which, "dfsph") == 0) return cmocka_run_group_tests_name("dam_break_dfsph", dfsph, NULL, NULL);
  if (strcmp(which, "dfsph_boundary") == 0)
    return cmocka_run_group_tests_name("dam_break_dfsph_boundary", dfsph_boundary, NULL, NULL);
  if (strcmp(which, "dfsph_capped") == 0)
    return cmocka_run_group_tests_name("dam_break_dfsph_capped", dfsph_capped, NULL, NULL);
  if (strcmp(which, "diffusion") == 0) {
    wcsph_features = SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION;
    return cmocka_run_group_tests_name("validation_dam_break_diffusion", wcsph, NULL, NULL);
  }
  return cmocka_run_group_tests_name("validation_dam_break", wcsph, NULL, NULL);
}
