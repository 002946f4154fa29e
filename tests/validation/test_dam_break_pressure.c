// SPDX-License-Identifier: MIT
/* The wall-pressure sensor of a dam break against a published measurement (issue 17 item 5):
 * Buchner (2002)'s sensor P1 (tests/data/buchner_2002_dam_break_p1.csv says where it is and
 * where the points come from). A column H high and 2H long collapses in a tank 5.366 H long; a
 * probe (sph_probe, EVERY_SUBSTEP) stands where P1's centre is, 0.267 H above the floor, half a
 * kernel radius off the far wall; its pressure over rho g H against the sensor's, in t sqrt(g/H):
 *   - the impact time, where p* first reaches 0.1 (the data's rise crosses it at t* = 2.48):
 *     within 5 % (the bound) with DAM_PRESSURE_STRICT=1 (the KNOWN_ISSUE ctests), else
 *     within 15 %: moving the lattice by 1e-7 m moves it between -3.6 % and +11.1 % at 16 lattice
 *     steps (plain; diffusion -0.2 % to +12.8 %) and +5.7 % to +11.1 % at 32 (docs/validation.md),
 *     so 5 % passed at 16 steps by the draw of the unperturbed lattice (CUDA read +5.8 %);
 *   - the plateau, the mean of p* over t* in [3.3, 4.5] after the impact's peak (the data's 0.55):
 *     within 20 % (the bound).
 * The experiment is 2D (a tank much wider than its water); here a slab 4 layers thick between
 * free-slip walls, H = 0.1 m (Froude scaling: t* and p* are the same at any H for an inviscid
 * flow), the walls in the density (so the fluid presses on the far wall with its pressure),
 * ideal gas k = 100 (c = 10 m/s, 10 sqrt(g H)), Mueller's viscosity 0.05 Pa s as the Martin & Moyce
 * validation (the default 1 Pa s slows a 10 cm flow: Reynolds number about 100). Cases: "plain" (the
 * summation density) and "diffusion" (SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION). CI: H
 * = 16 lattice steps; SPH_VALIDATION_FULL=1 (scripts/validate --full): 32. DAM_PRESSURE_MEASURE=1 prints
 * without asserting; DAM_PRESSURE_PERTURB=SEED moves the lattice by up to 1e-7 m. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"
#include "validation_util.h"

#ifndef SPH_TEST_DATA_DIR
#define SPH_TEST_DATA_DIR "tests/data"
#endif

static const double kGravity = 9.81;
static const double kHeight = 0.1; /* H, m */
static const double kTankLength = 5.366;
static const double kSensorHeight = 0.16 / 0.6; /* P1's centre over H */

#define MAX_POINTS 256
#define MAX_FRAMES 4096

static int measuring(void) { return getenv("DAM_PRESSURE_MEASURE") != NULL; }

/* The impact time's bound (see the top). */
static double impact_bound(void) { return getenv("DAM_PRESSURE_STRICT") ? 0.05 : 0.15; }

/* The data file's (t*, p*) points; returns their count. */
static int read_data(double* t, double* p) {
  char line[256];
  int n = 0;
  FILE* f = fopen(SPH_TEST_DATA_DIR "/buchner_2002_dam_break_p1.csv", "r");
  assert_non_null(f);
  while (fgets(line, sizeof line, f) && n < MAX_POINTS)
    if (line[0] != '#' && sscanf(line, "%lf,%lf", &t[n], &p[n]) == 2) ++n;
  fclose(f);
  return n;
}

/* The first t* where the series reaches `level`, by linear interpolation (-1: never). */
static double crossing(const double* t, const double* p, int n, double level) {
  for (int i = 1; i < n; ++i)
    if (p[i - 1] < level && p[i] >= level)
      return t[i - 1] + (level - p[i - 1]) / (p[i] - p[i - 1]) * (t[i] - t[i - 1]);
  return -1.0;
}

/* The time mean of the piecewise linear series over [a, b]. */
static double window_mean(const double* t, const double* p, int n, double a, double b) {
  double sum = 0.0, span = 0.0;
  for (int i = 1; i < n; ++i) {
    const double lo = fmax(a, t[i - 1]), hi = fmin(b, t[i]);
    if (hi <= lo) continue;
    {
      const double s = (t[i] - t[i - 1]) > 0.0 ? 1.0 / (t[i] - t[i - 1]) : 0.0;
      const double plo = p[i - 1] + (p[i] - p[i - 1]) * (lo - t[i - 1]) * s;
      const double phi = p[i - 1] + (p[i] - p[i - 1]) * (hi - t[i - 1]) * s;
      sum += 0.5 * (plo + phi) * (hi - lo);
      span += hi - lo;
    }
  }
  return span > 0.0 ? sum / span : 0.0;
}

/* check_plateau: assert the plateau's bound too (the KNOWN_ISSUE cases; see main). */
static void dam_break_pressure(uint32_t features, const char* name, int check_plateau) {
  /* lattice steps over H (DAM_PRESSURE_STEPS=N measures another) */
  const uint32_t across = getenv("DAM_PRESSURE_STEPS") ? (uint32_t)atoi(getenv("DAM_PRESSURE_STEPS"))
                          : validation_full()          ? 32u
                                                       : 16u;
  const double step = kHeight / across;
  const uint32_t layers[3] = {2u * across, across, 4u};
  /* The walls stand (spacing - step) / 2 beyond the lattice's outer mid-planes, where the walls
   * in the density hold a resting layer (docs/validation.md, "Loads on a hydrostatic tank's side
   * wall"): a lattice against them at step / 2 starts compressed and throws droplets, one of
   * which reached the far wall at t* = 1.05 in a first try. */
  const double film = 0.5 * (sqrt(2.0) - 1.0) * step;
  const double length = kTankLength * kHeight - film; /* the far wall from the lattice's origin */
  const double tank_min[3] = {-film, -film, -film}, tank_max[3] = {length, 3.0 * kHeight, 4.0 * step + film};
  const double time_scale = sqrt(kHeight / kGravity), pressure_scale = 1000.0 * kGravity * kHeight;
  /* The impact-only cases stop at t* = 3.2, after the latest impact their bound admits (1.15 x
   * 2.478 = 2.85); the plateau's window ends at 4.5, so the whole cases, measuring runs and
   * scripts/validate's series (SPH_VALIDATION_OUT) go on to 5. */
  const int whole = check_plateau || measuring() || getenv("SPH_VALIDATION_OUT") != NULL;
  const double frame = 0.02 * time_scale, end = whole ? 5.0 : 3.2;
  static double sim_t[MAX_FRAMES], sim_p[MAX_FRAMES], data_t[MAX_POINTS], data_p[MAX_POINTS];
  float* lattice = NULL;
  uint32_t n = 0;
  int frames = 0, points;
  support_world w;
  sph_sdf* sdf = NULL;
  sph_world_def def;
  sph_world_params params;
  sph_probe_def probe_def;
  sph_probe_id probe;
  double t_sim, t_data, plateau_sim, plateau_data;
  assert_int_equal(support_fcc_box(layers, step, NULL, &lattice, &n), SPH_OK);
  sph_world_params_init(&params);
  if (getenv("DAM_PRESSURE_HYDROSTATIC_START")) {
    /* Measuring only: the column starts in hydrostatic equilibrium, as the water behind the gate
     * was: with p = k (rho - rho0) and p = rho0 g d, each layer compressed by rho0 / rho(d),
     * y' = ln((1 + a H) / (1 + a (H - y))) / a with a = g / k (docs/validation.md: it does not
     * narrow the impact's spread at 16 steps). */
    const double a = kGravity / params.stiffness;
    for (uint32_t i = 0; i < n; ++i) {
      const double y = lattice[3 * i + 1];
      lattice[3 * i + 1] = (float)(log((1.0 + a * kHeight) / (1.0 + a * (kHeight - y))) / a);
    }
  }
  if (getenv("DAM_PRESSURE_PERTURB")) {
    /* Measuring only: every lattice coordinate moved by up to 1e-7 m (a generator seeded with
     * the variable's value), to see how far rounding alone moves the readings. */
    uint64_t state = strtoull(getenv("DAM_PRESSURE_PERTURB"), NULL, 10) * 0x9E3779B97F4A7C15ull;
    for (uint32_t i = 0; i < 3 * n; ++i) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      lattice[i] += (float)(((double)(state >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0) * 1e-7);
    }
  }
  sph_world_def_init(&def);
  def.particle_spacing = (float)(step * sqrt(2.0));
  def.capacity = n;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | features;
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  params.viscosity = 0.05f; /* the Martin & Moyce validation's (tests/support/dam_break.c) */
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, &params));
  EXPECT_OK(support_tank_between(w.context, w.world, tank_min, tank_max, 0.5 * step, 0.0f, &sdf, NULL));
  EXPECT_OK(support_spawn(w.world, lattice, NULL, n));
  free(lattice);
  EXPECT_OK(sph_probe_def_init(&probe_def));
  probe_def.sampling = SPH_PROBE_EVERY_SUBSTEP;
  probe_def.position.x = (float)(length - 0.5 * w.def.kernel_radius);
  probe_def.position.y = (float)(kSensorHeight * kHeight);
  probe_def.position.z = (float)(2.0 * step);
  EXPECT_OK(sph_probe_create(w.world, &probe_def, &probe));
  while (frames < MAX_FRAMES && (frames + 1) * frame <= end * time_scale + 1e-9) {
    sph_probe_reading r;
    EXPECT_OK(sph_world_step(w.world, (float)frame));
    EXPECT_OK(sph_probe_reading_init(&r));
    EXPECT_OK(sph_probe_get_reading(w.world, probe, &r));
    sim_t[frames] = (frames + 0.5) * frame / time_scale; /* the frame's mean */
    sim_p[frames] = r.pressure / pressure_scale;
    ++frames;
  }
  points = read_data(data_t, data_p);
  t_sim = crossing(sim_t, sim_p, frames, 0.1);
  t_data = crossing(data_t, data_p, points, 0.1);
  plateau_sim = window_mean(sim_t, sim_p, frames, 3.3, 4.5);
  plateau_data = window_mean(data_t, data_p, points, 3.3, 4.5);
  {
    double peak = 0.0;
    for (int i = 0; i < frames; ++i) peak = fmax(peak, sim_p[i]);
    print_message(
        "dam break pressure (%s, %u particles, H = %u steps): impact t* = %.3f (Buchner %.3f, %+.1f %%), ",
        name, n, across, t_sim, t_data, 100.0 * (t_sim / t_data - 1.0));
    if (end >= 4.5)
      print_message("plateau p* = %.3f (Buchner %.3f, %+.1f %%), ", plateau_sim, plateau_data,
                    100.0 * (plateau_sim / plateau_data - 1.0));
    else
      print_message("plateau not run (t* <= %.1f), ", end);
    print_message("peak of the frames' means %.3f\n", peak);
  }
  {
    FILE* out =
        validation_open_output(features ? "dam_break_pressure_diffusion.csv" : "dam_break_pressure.csv");
    if (out) {
      fprintf(out, "t_star,p_star\n");
      for (int i = 0; i < frames; ++i) fprintf(out, "%.5f,%.5f\n", sim_t[i], sim_p[i]);
      fclose(out);
    }
  }
  assert_true((t_sim > 0.0 && fabs(t_sim / t_data - 1.0) <= impact_bound()) || measuring());
  assert_true(!check_plateau || fabs(plateau_sim / plateau_data - 1.0) <= 0.2 || measuring());
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

static void test_plain_impact(void** state) {
  (void)state;
  dam_break_pressure(SPH_FEATURE_NONE, "plain", 0);
}

static void test_diffusion_impact(void** state) {
  (void)state;
  dam_break_pressure(SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION, "diffusion", 0);
}

static void test_plain(void** state) {
  (void)state;
  dam_break_pressure(SPH_FEATURE_NONE, "plain", 1);
}

static void test_diffusion(void** state) {
  (void)state;
  dam_break_pressure(SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION, "diffusion", 1);
}

/* Each case is its own ctest (tests/validation/CMakeLists.txt): the impact cases run in CI with
 * the measured spread's bound; the bounds (DAM_PRESSURE_STRICT=1: the impact within 5 %,
 * and in the whole cases the plateau within 20 %) are registered as KNOWN_ISSUE
 * (docs/validation.md, "Dam break: the wall-pressure sensor"). */
int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plain_impact),
      cmocka_unit_test(test_diffusion_impact),
      cmocka_unit_test(test_plain),
      cmocka_unit_test(test_diffusion),
  };
  if (argc > 1) cmocka_set_test_filter(argv[1]);
  return cmocka_run_group_tests_name("dam_break_pressure", tests, NULL, NULL);
}
