// SPDX-License-Identifier: MIT
/* Hydrostatic tank: water at rest in a closed box under gravity, the interior's pressure against
 * the exact equilibrium of the equation of state in use within 3 % (DFSPH: 0.5 %), no particle
 * across the floor. The cases: the ideal gas and Tait's equation, the walls in the density, DFSPH;
 * what is compared and why: hydrostatic_tank.c. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hydrostatic_tank.h"
#include "validation_util.h"

/* The tank of the case's equation of state at the resolution asked for: 16 x 30 x 16 layers for
 * 1 s in CI, 32 x 60 x 32 for 4 s at full resolution. */
static void run_tank_at_resolution(const char* name, sph_equation_of_state eos, uint32_t features,
                                   double bound) {
  tank_case tc = {.name = name,
                  .eos = eos,
                  .solver = SPH_SOLVER_WCSPH,
                  .features = features,
                  .bound = bound,
                  .width_layers = 16,
                  .depth_layers = 30,
                  .step = 0.01,
                  .seconds = 1.0};
  if (validation_full()) {
    tc.width_layers = 32;
    tc.depth_layers = 60;
    tc.step = 0.01;
    /* The 0.6 m deep tank keeps a sloshing mode (kinetic energy swinging 0.01-0.35 J with a
     * period of about 1.2 s at the default viscosity, measured on the H100), so the averaging
     * window, the second half of the run, must span more than one period: 4 s. With 2 s the
     * window caught less than one swing and the Tait tank read 1.80 % mean, 3.80 % worst. */
    tc.seconds = 4.0;
  }
  run_tank(&tc);
}

static void test_hydrostatic_ideal_gas(void** state) {
  (void)state;
  run_tank_at_resolution("ideal gas p = k (rho - rho0), k = 100", SPH_EOS_IDEAL_GAS, 0u, 0.03);
}

static void test_hydrostatic_ideal_gas_boundary(void** state) {
  (void)state;
  run_tank_at_resolution("ideal gas, k = 100, boundary density", SPH_EOS_IDEAL_GAS,
                         SPH_FEATURE_BOUNDARY_DENSITY, 0.03);
}

/* DFSPH (issue 16 item 4): the interior within 0.5 % of rho0 g d (the bound) with the
 * walls in the density and the solves (SPH_FEATURE_BOUNDARY_DENSITY); without them, the walls
 * only stop particles (the collision response and the solves' contacts) and the particles
 * within h of them read low densities: `dfsph_walls_unmodelled` runs that case and reports it
 * against the weakly compressible scheme's 3 %. A 12 x 24 x 12 tank for 4 s (averaged over the
 * last 2 s), 24 x 48 x 24 at full resolution.
 * dt_max 4 ms: measured at 4 s, interior 0.46 % mean, 0.67 % worst; at the default 1 ms 2.83 % /
 * 5.26 %; at 6 and 8 ms the walls throw particles and the tank never settles. A density bound of
 * 1e-4 (dfsph_tight) gives 0.55 % / 1.05 %: the solve's residual is not what limits it
 * (docs/validation.md, "DFSPH: hydrostatic tank"). Session 13: 0.32 % / 0.85 % today, 0.75 % /
 * 1.61 % at 16 layers; the pressure is the weight's multiplier through a discrete gradient 2-3 %
 * off on the settled packing, which the diagnostics (tc.gauges) report. */
static tank_case dfsph_tank_wide(const char* name, uint32_t features, double bound, float density_error,
                                 uint32_t width_layers) {
  tank_case tc = {.name = name,
                  .eos = SPH_EOS_IDEAL_GAS,
                  .solver = SPH_SOLVER_DFSPH,
                  .features = features,
                  .bound = bound,
                  .width_layers = width_layers,
                  .depth_layers = 24,
                  .step = 0.01,
                  .seconds = 4.0,
                  .dt_max = 0.004f,
                  .density_error = density_error};
  if (validation_full()) {
    tc.width_layers = width_layers > 24u ? width_layers : 24u;
    tc.depth_layers = 48;
  }
  /* HYDRO_LAYERS=N measures a tank N layers across and 2 N deep (the resolution study,
   * docs/validation.md); HYDRO_SECONDS and HYDRO_DT_MAX (s) another length or step, HYDRO_KERNEL
   * another kernel radius (in spacings). */
  if (getenv("HYDRO_LAYERS")) {
    tc.width_layers = (uint32_t)atoi(getenv("HYDRO_LAYERS"));
    tc.depth_layers = 2u * tc.width_layers;
  }
  /* HYDRO_WIDTH=N: N layers across at the case's depth (more particles a slice, the same column). */
  if (getenv("HYDRO_WIDTH")) tc.width_layers = (uint32_t)atoi(getenv("HYDRO_WIDTH"));
  if (getenv("HYDRO_SECONDS")) tc.seconds = atof(getenv("HYDRO_SECONDS"));
  /* HYDRO_STEP (m): another lattice step (the resolution at a given depth: the deep tanks' step
   * against h, docs/validation.md). */
  if (getenv("HYDRO_STEP")) tc.step = atof(getenv("HYDRO_STEP"));
  if (getenv("HYDRO_DT_MAX")) tc.dt_max = (float)atof(getenv("HYDRO_DT_MAX"));
  /* HYDRO_DT_MIN (s): the step's floor; at HYDRO_DT_MAX it pins every substep. */
  if (getenv("HYDRO_DT_MIN")) tc.dt_min = (float)atof(getenv("HYDRO_DT_MIN"));
  if (getenv("HYDRO_KERNEL")) tc.kernel_spacings = (float)atof(getenv("HYDRO_KERNEL"));
  if (getenv("HYDRO_FLAGS")) tc.dfsph_flags = (uint32_t)atoi(getenv("HYDRO_FLAGS"));
  /* HYDRO_FRAME (s): another frame length; at dt_max every frame is one substep, so the particles'
   * reading (read at frame ends) samples every substep, as the gauges do (docs/validation.md). The
   * frames also take other substeps where the speed limit binds (the start-up), so the run settles
   * into another packing: 4 ms frames read 0.32-0.81 % mean over six perturbed runs, 20 ms frames
   * 0.29-0.56 % (docs/physics.md, "How a frame splits into substeps"). */
  if (getenv("HYDRO_FRAME")) tc.frame = (float)atof(getenv("HYDRO_FRAME"));
  tc.gauges = 1;
  return tc;
}

static tank_case dfsph_tank(const char* name, uint32_t features, double bound, float density_error) {
  return dfsph_tank_wide(name, features, bound, density_error, 12u);
}

static void run_dfsph_tank(const char* name, uint32_t features, double bound, float density_error) {
  const tank_case tc = dfsph_tank(name, features, bound, density_error);
  run_tank(&tc);
}

static void test_hydrostatic_dfsph(void** state) {
  (void)state;
  run_dfsph_tank("DFSPH, boundary density, p = rho0 g d", SPH_FEATURE_BOUNDARY_DENSITY, 0.005, 0.0f);
}

/* The same with the solves' pressure gradient corrected (SPH_DFSPH_CORRECTED_GRADIENT,
 * physics/dfsph_gradient_correction.h): the 0.5 % on every interior slice, on a tank 24
 * layers wide (24 x 24 x 24, 6,912 particles). Each particle's pressure scatters 1.5-2.2 % about
 * rho0 g d (6-8 % at the default gradient), so a slice's mean over about 420 interior particles
 * has a standard error of 0.08-0.13 %; 12 wide (about 50 particles a slice) it was 0.3-0.6 %, and the
 * worst of six slices read 0.16 % (CPU, session 16), 0.66 % (H200) or 1.03 % (CPU, at 30819b0): a
 * draw, not a bound held. Measured 24 wide (CPU, session 26): 0.13 % mean, 0.27 % worst; with the
 * lattice moved by up to 1e-7 m (HYDRO_PERTURB=1, 2) 0.08 % / 0.19 % and 0.06 % / 0.18 %; the
 * gauges 0.18-0.20 % worst (docs/validation.md, "DFSPH: hydrostatic tank", session 26). The
 * default gradient on the same tank reads 0.42 % / 0.72 % (validation_hydrostatic_dfsph_KNOWN_ISSUE). */
static void test_hydrostatic_dfsph_corrected(void** state) {
  tank_case tc = dfsph_tank_wide("DFSPH, boundary density, corrected gradient, p = rho0 g d",
                                 SPH_FEATURE_BOUNDARY_DENSITY, 0.005, 0.0f, 24u);
  (void)state;
  tc.dfsph_flags |= SPH_DFSPH_CORRECTED_GRADIENT;
  run_tank(&tc);
}

/* The same at a density bound of 1e-4 (a tenth of the default), to tell the solve's residual
 * correction from the rest: measured 0.55 % mean, 1.05 % worst, no better than the default's
 * (258 s of CPU here). A measurement (argv `dfsph_tight`), not a ctest. */
static void test_hydrostatic_dfsph_tight(void** state) {
  (void)state;
  run_dfsph_tank("DFSPH, boundary density, bound 1e-4, p = rho0 g d", SPH_FEATURE_BOUNDARY_DENSITY, 0.005,
                 1e-4f);
}

/* The doc's next experiments for the 0.5 % (docs/validation.md, "DFSPH: hydrostatic tank"), a
 * measurement (argv `dfsph_settled`), not a ctest: 8 s, every velocity zeroed each 0.1 s for the
 * first 2 s (the residual motion damped while it settles), every substep sampled (4 ms frames at
 * dt_max 4 ms) and averaged over the last 6 s. */
static void test_hydrostatic_dfsph_settled(void** state) {
  tank_case tc = dfsph_tank("DFSPH, boundary density, damped, every substep over 6 s, p = rho0 g d",
                            SPH_FEATURE_BOUNDARY_DENSITY, 0.005, 0.0f);
  (void)state;
  tc.seconds = 8.0;
  tc.frame = 0.004f;
  tc.window = 0.75;
  tc.damp_until = 2.0;
  run_tank(&tc);
}

static void test_hydrostatic_dfsph_walls_unmodelled(void** state) {
  (void)state;
  run_dfsph_tank("DFSPH, walls by collision only, p = rho0 g d", 0u, 0.03, 0.0f);
}

static void test_hydrostatic_tait(void** state) {
  (void)state;
  run_tank_at_resolution("Tait, c = 10 m/s", SPH_EOS_TAIT, 0u, 0.03);
}

/* argv[1] picks one case by its name; none runs those marked by default (tait and ideal_gas). */
typedef struct named_case {
  const char* name;  /* argv[1] */
  const char* group; /* cmocka's group */
  int by_default;
  struct CMUnitTest test;
} named_case;

int main(int argc, char** argv) {
  static const named_case cases[] = {
      {"tait", "hydrostatic_tait", 1, cmocka_unit_test(test_hydrostatic_tait)},
      {"ideal_gas", "hydrostatic_ideal_gas", 1, cmocka_unit_test(test_hydrostatic_ideal_gas)},
      {"ideal_gas_boundary", "hydrostatic_ideal_gas_boundary", 0,
       cmocka_unit_test(test_hydrostatic_ideal_gas_boundary)},
      {"dfsph", "hydrostatic_dfsph", 0, cmocka_unit_test(test_hydrostatic_dfsph)},
      {"dfsph_corrected", "hydrostatic_dfsph_corrected", 0,
       cmocka_unit_test(test_hydrostatic_dfsph_corrected)},
      {"dfsph_tight", "hydrostatic_dfsph_tight", 0, cmocka_unit_test(test_hydrostatic_dfsph_tight)},
      {"dfsph_settled", "hydrostatic_dfsph_settled", 0, cmocka_unit_test(test_hydrostatic_dfsph_settled)},
      {"dfsph_walls_unmodelled", "hydrostatic_dfsph_walls_unmodelled", 0,
       cmocka_unit_test(test_hydrostatic_dfsph_walls_unmodelled)},
  };
  int failed = 0, ran = 0;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
    if (argc < 2 ? cases[i].by_default : strcmp(argv[1], cases[i].name) == 0) {
      failed += _cmocka_run_group_tests(cases[i].group, &cases[i].test, 1, NULL, NULL);
      ++ran;
    }
  if (ran == 0) { /* a name that is no case: an error, not a run of none that passes */
    fprintf(stderr, "validation_hydrostatic_tank: no case named '%s'\n", argv[1]);
    return 2;
  }
  return failed;
}
