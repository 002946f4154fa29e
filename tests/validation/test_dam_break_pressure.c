// SPDX-License-Identifier: MIT
/* The wall-pressure sensor of a dam break against a published measurement (issue 17 item 5):
 * Buchner (2002)'s sensor P1 (tests/data/buchner_2002_dam_break_p1.csv says where it is and
 * where the points come from). A column H high and 2H long collapses in a tank 5.366 H long; a
 * probe (sph_probe, EVERY_SUBSTEP) stands where P1's centre is, 0.267 H above the floor, on the
 * far wall's surface (a flush transducer's place; the probe's Shepard mean reads the fluid within
 * a kernel radius of it); its pressure over rho g H against the sensor's, in t sqrt(g/H):
 *   - the impact time, where p* first reaches 0.1 (the data's rise crosses it at t* = 2.48);
 *   - the plateau, the mean of p* over t* in [3.3, 4.5] after the impact's peak (the data's 0.55).
 * One run's impact moves by several percent when the lattice moves by 1e-7 m, so the issue's
 * bounds (impact within 5 %, plateau within 20 %) are asserted on the mean of an ensemble of such
 * draws (test_plain_ensemble, ~50 s on 2 cores: scripts/validate runs it); the CI cases assert
 * one draw's impact within 15 % (the draws' spread; DAM_PRESSURE_STRICT=1: 5 %).
 * The experiment is 2D (a tank much wider than its water); here a slab 4 layers thick between
 * free-slip walls, H = 0.1 m (Froude scaling: t* and p* are the same at any H for an inviscid
 * flow), the walls in the density (so the fluid presses on the far wall with its pressure),
 * ideal gas k = 225 (c = 15 m/s, kSoundSpeed), Mueller's viscosity 0.05 Pa s as the Martin & Moyce
 * validation (the default 1 Pa s slows a 10 cm flow: Reynolds number about 100). Cases: "plain" (the
 * summation density) and "diffusion" (SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION;
 * both meet the bounds on their six-draw ensembles). CI: H = 16 lattice steps;
 * SPH_VALIDATION_FULL=1 (scripts/validate --full): 32. Measuring knobs (docs/validation.md):
 * DAM_PRESSURE_MEASURE=1 prints without asserting (and reads probes half and a quarter kernel
 * radius off the wall and a gauge at it); DAM_PRESSURE_STEPS=N, DAM_PRESSURE_PERTURB=SEED,
 * DAM_PRESSURE_ENSEMBLE=DRAWS, DAM_PRESSURE_FIRST_DRAW=K, DAM_PRESSURE_C=m/s, DAM_PRESSURE_EOS=tait,
 * DAM_PRESSURE_SOLVER=dfsph, DAM_PRESSURE_PROBE_OFFSET=kernel radii, DAM_PRESSURE_FEATURES=bits,
 * DAM_PRESSURE_HYDROSTATIC_START=1, DAM_PRESSURE_SLAB=layers (the slab's thickness, default 4),
 * DAM_PRESSURE_VISCOSITY=Pa s (default 0.05), DAM_PRESSURE_ALPHA=alpha and DAM_PRESSURE_VISCOSITY_RULE=h (a
 * viscosity in proportion to h: case_viscosity), DAM_PRESSURE_STEP_FACTOR=lambda (the acoustic limit's
 * factor, default the library's 0.4), DAM_PRESSURE_TENSION=tau (sph_world_params.tension_ratio, the equation
 * of state's bounded tension; default 0, the clamp; docs/validation.md, "Session 21: a bounded tension"). */
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
/* c = 15 m/s (k = 225), 15 sqrt(g H): 7.6 times the surge front's 2 sqrt(g H), inside the 10-20
 * sqrt(g H) of the literature's weakly compressible runs of this case (Marrone et al. 2011: 20);
 * docs/validation.md has the readings at c = 10 and 20 m/s and with Tait's law. */
static const double kSoundSpeed = 15.0;

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

/* Measuring knobs (docs/validation.md): DAM_PRESSURE_EOS=tait (Tait, gamma 7) with
 * DAM_PRESSURE_C=c (m/s: Tait's speed of sound, or k = c^2 for the ideal gas; default kSoundSpeed),
 * DAM_PRESSURE_SOLVER=dfsph (no equation of state; refuses the normalised density). */
static void scene_physics(sph_world_def* def, sph_world_params* params) {
  const char* eos = getenv("DAM_PRESSURE_EOS");
  const char* solver = getenv("DAM_PRESSURE_SOLVER");
  if (eos && strcmp(eos, "tait") == 0) def->equation_of_state = SPH_EOS_TAIT;
  if (solver && strcmp(solver, "dfsph") == 0) def->solver = SPH_SOLVER_DFSPH;
  const double c = getenv("DAM_PRESSURE_C") ? atof(getenv("DAM_PRESSURE_C")) : kSoundSpeed;
  params->stiffness = (float)(c * c);
}

static void scene_tait(sph_world* world, const sph_world_def* def) {
  sph_tait_params tait;
  if (def->equation_of_state != SPH_EOS_TAIT) return;
  EXPECT_OK(sph_tait_params_init(&tait));
  tait.speed_of_sound = (float)(getenv("DAM_PRESSURE_C") ? atof(getenv("DAM_PRESSURE_C")) : kSoundSpeed);
  EXPECT_OK(sph_world_set_tait_params(world, &tait));
}

/* The case's numerical viscosity, Mueller's mu: 0.05 Pa s, the Martin & Moyce validation's
 * (tests/support/dam_break.c), at every resolution. Measuring knobs (docs/validation.md, "Session
 * 20: a viscosity in proportion to h"): DAM_PRESSURE_VISCOSITY=mu (Pa s) another constant;
 * DAM_PRESSURE_ALPHA=alpha the viscosity of Monaghan's artificial viscosity, mu = rho0 alpha c h / 20
 * (its shear viscosity nu = alpha c h_M / 10 in 3D in the continuum limit, whatever the kernel, with
 * h_M = h / 2 the smoothing length of a kernel whose radius is h; Mueller's term is consistent,
 * sum_j V_j (v_j - v_i) lap W -> lap v), so in proportion to h and c; DAM_PRESSURE_VISCOSITY_RULE=h
 * the same anchored at 0.05 Pa s at 16 steps and 15 m/s (alpha = 0.0042; 0.025 at 32 steps), exactly
 * 0.05 there. mu in proportion to h holds the plateau closer than a constant 0.05 at 24-64 steps
 * but still falls (-16 % at 32 and 48, -21 % at 64 on the H200), so it is not the case's rule. */
static const double kRestDensity = 1000.0;
static const double kViscosity = 0.05; /* Pa s */

/* The kernel radius, the library's default 1.8 particle spacings (the FCC spacing step sqrt 2). */
static double kernel_radius(double step) { return 1.8 * step * sqrt(2.0); }

/* mu for the lattice step and the speed of sound c (the knobs above). */
static double case_viscosity(double step, double c) {
  const char* rule = getenv("DAM_PRESSURE_VISCOSITY_RULE");
  if (getenv("DAM_PRESSURE_VISCOSITY")) return atof(getenv("DAM_PRESSURE_VISCOSITY"));
  if (getenv("DAM_PRESSURE_ALPHA"))
    return kRestDensity * atof(getenv("DAM_PRESSURE_ALPHA")) * c * kernel_radius(step) / 20.0;
  if (rule && strcmp(rule, "h") == 0) return kViscosity * (step / (kHeight / 16.0)) * (c / kSoundSpeed);
  return kViscosity;
}

/* One run's readings against Buchner's, relative (0.01 = 1 % late or high). */
typedef struct reading {
  double impact, plateau;
} reading;

/* whole_run: on to t* = 5 for the plateau; seed: 0 the lattice as built, else every coordinate moved
 * by up to 1e-7 m by a generator seeded with it (DAM_PRESSURE_PERTURB=SEED sets it for a case). */
static reading dam_break_pressure(uint32_t features, const char* name, int whole_run, uint64_t seed) {
  /* lattice steps over H (DAM_PRESSURE_STEPS=N measures another) */
  const uint32_t across = getenv("DAM_PRESSURE_STEPS") ? (uint32_t)atoi(getenv("DAM_PRESSURE_STEPS"))
                          : validation_full()          ? 32u
                                                       : 16u;
  const double step = kHeight / across;
  /* the slab's thickness in lattice layers (DAM_PRESSURE_SLAB=N measures another) */
  const uint32_t slab = getenv("DAM_PRESSURE_SLAB") ? (uint32_t)atoi(getenv("DAM_PRESSURE_SLAB")) : 4u;
  const uint32_t layers[3] = {2u * across, across, slab};
  /* The walls stand (spacing - step) / 2 beyond the lattice's outer mid-planes, where the walls
   * in the density hold a resting layer (docs/validation.md, "Loads on a hydrostatic tank's side
   * wall"): a lattice against them at step / 2 starts compressed and throws droplets, one of
   * which reached the far wall at t* = 1.05 in a first try. */
  const double film = 0.5 * (sqrt(2.0) - 1.0) * step;
  const double length = kTankLength * kHeight - film; /* the far wall from the lattice's origin */
  const double tank_min[3] = {-film, -film, -film}, tank_max[3] = {length, 3.0 * kHeight, slab * step + film};
  const double time_scale = sqrt(kHeight / kGravity), pressure_scale = 1000.0 * kGravity * kHeight;
  /* The impact-only cases stop at t* = 3.2, after the latest impact their bound admits (1.15 x
   * 2.478 = 2.85); the plateau's window ends at 4.5, so the whole cases, measuring runs and
   * scripts/validate's series (SPH_VALIDATION_OUT) go on to 5. */
  const int whole = whole_run || measuring() || getenv("SPH_VALIDATION_OUT") != NULL;
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
  sph_probe_id probe, extra[4];
  double gauge_scale = 1.0;
  static double extra_p[3][MAX_FRAMES], side_p[MAX_FRAMES], wall_fill[MAX_FRAMES], wall_u[MAX_FRAMES],
      wall_v[MAX_FRAMES];
  sph_probe_id side;
  memset(&side, 0, sizeof side);
  /* the probe's distance from the far wall in kernel radii (DAM_PRESSURE_PROBE_OFFSET measures another) */
  const double offset = getenv("DAM_PRESSURE_PROBE_OFFSET") ? atof(getenv("DAM_PRESSURE_PROBE_OFFSET")) : 0.0;
  double t_sim, t_data, plateau_sim, plateau_data;
  assert_true(slab >= 2u); /* a probe on the centre plane needs fluid on both sides of it */
  assert_int_equal(support_fcc_box(layers, step, NULL, &lattice, &n), SPH_OK);
  sph_world_params_init(&params);
  sph_world_def_init(&def);
  scene_physics(&def, &params);
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
  if (!seed && getenv("DAM_PRESSURE_PERTURB")) seed = strtoull(getenv("DAM_PRESSURE_PERTURB"), NULL, 10);
  /* Rounding-sized moves (the ensemble's draws): how far rounding alone moves the readings. */
  if (seed) support_nudge(lattice, n, seed, 1e-7);
  def.particle_spacing = (float)(step * sqrt(2.0));
  def.capacity = n;
  /* DAM_PRESSURE_FEATURES=BITS (measuring only) replaces the case's feature bits */
  if (getenv("DAM_PRESSURE_FEATURES")) features = (uint32_t)strtoul(getenv("DAM_PRESSURE_FEATURES"), NULL, 0);
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | features;
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  params.viscosity = (float)case_viscosity(step, sqrt(params.stiffness));
  if (getenv("DAM_PRESSURE_STEP_FACTOR"))
    params.step_factor = (float)atof(getenv("DAM_PRESSURE_STEP_FACTOR"));
  if (getenv("DAM_PRESSURE_TENSION")) params.tension_ratio = (float)atof(getenv("DAM_PRESSURE_TENSION"));
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, &params));
  scene_tait(w.world, &def);
  EXPECT_OK(support_tank_between(w.context, w.world, tank_min, tank_max, 0.5 * step, 0.0f, &sdf, NULL));
  EXPECT_OK(support_spawn(w.world, lattice, NULL, n));
  free(lattice);
  EXPECT_OK(sph_probe_def_init(&probe_def));
  probe_def.sampling = SPH_PROBE_EVERY_SUBSTEP;
  probe_def.position.x = (float)(length - offset * w.def.kernel_radius);
  probe_def.position.y = (float)(kSensorHeight * kHeight);
  probe_def.position.z = (float)(0.5 * slab * step); /* the slab's centre plane */
  EXPECT_OK(sph_probe_create(w.world, &probe_def, &probe));
  if (measuring()) {
    /* Measuring only: a probe on the far wall at the sensor's height in the first layer's plane by
     * the near side wall (the slab's edge, against the centre plane's) */
    probe_def.position.z = (float)(0.5 * step);
    EXPECT_OK(sph_probe_create(w.world, &probe_def, &side));
    probe_def.position.z = (float)(0.5 * slab * step);
    /* Measuring only: probes half and a quarter kernel radius off the wall, and a gauge half a
     * kernel radius off it from below the floor (the water's height at the wall: the hydrostatic
     * pressure at the sensor, rho g (eta - y_s)). */
    probe_def.position.x = (float)(length - 0.5 * w.def.kernel_radius);
    EXPECT_OK(sph_probe_create(w.world, &probe_def, &extra[0]));
    probe_def.position.x = (float)(length - 0.25 * w.def.kernel_radius);
    EXPECT_OK(sph_probe_create(w.world, &probe_def, &extra[1]));
    probe_def.kind = SPH_PROBE_GAUGE;
    probe_def.position.x = (float)(length - 0.5 * w.def.kernel_radius);
    probe_def.position.y = (float)(-film - w.def.kernel_radius);
    probe_def.length = (float)(3.0 * kHeight);
    EXPECT_OK(sph_probe_create(w.world, &probe_def, &extra[2]));
    /* its mirror image half a kernel radius off the near wall, inside the column at the start: the
     * thin slab and the wall cut the gauge's kernel, so its first reading over H calibrates it */
    probe_def.position.x = (float)(-film + 0.5 * w.def.kernel_radius);
    EXPECT_OK(sph_probe_create(w.world, &probe_def, &extra[3]));
  }
  while (frames < MAX_FRAMES && (frames + 1) * frame <= end * time_scale + 1e-9) {
    sph_probe_reading r;
    EXPECT_OK(sph_world_step(w.world, (float)frame));
    EXPECT_OK(sph_probe_reading_init(&r));
    EXPECT_OK(sph_probe_get_reading(w.world, probe, &r));
    sim_t[frames] = (frames + 0.5) * frame / time_scale; /* the frame's mean */
    sim_p[frames] = r.pressure / pressure_scale;
    wall_fill[frames] = r.kernel_sum;
    wall_u[frames] = r.velocity.x / sqrt(kGravity * kHeight);
    wall_v[frames] = r.velocity.y / sqrt(kGravity * kHeight);
    if (measuring()) {
      sph_probe_reading e;
      EXPECT_OK(sph_probe_reading_init(&e));
      EXPECT_OK(sph_probe_get_reading(w.world, side, &e));
      side_p[frames] = e.pressure / pressure_scale;
    }
    if (measuring() && frames == 0) {
      EXPECT_OK(sph_probe_get_reading(w.world, extra[3], &r));
      gauge_scale = (r.water_height - film) / kHeight;
    }
    for (int k = 0; measuring() && k < 3; ++k) {
      EXPECT_OK(sph_probe_get_reading(w.world, extra[k], &r));
      extra_p[k][frames] =
          k < 2 ? r.pressure / pressure_scale
                : fmax(0.0, (r.water_height - film) / gauge_scale - kSensorHeight * kHeight) / kHeight;
    }
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
    if (measuring())
      print_message(
          "  plateau p* at 0.5 h off the wall %.3f, at 0.25 h %.3f; hydrostatic (eta - y_s) / H %.3f (gauge "
          "scale %.3f); "
          "impact at 0.5 h %.3f, at 0.25 h %.3f\n",
          window_mean(sim_t, extra_p[0], frames, 3.3, 4.5), window_mean(sim_t, extra_p[1], frames, 3.3, 4.5),
          window_mean(sim_t, extra_p[2], frames, 3.3, 4.5), gauge_scale,
          crossing(sim_t, extra_p[0], frames, 0.1), crossing(sim_t, extra_p[1], frames, 0.1));
    if (measuring())
      print_message(
          "  slab %u layers, viscosity %.4g Pa s (alpha %.4f): plateau p* by the side wall %.3f; the "
          "sensor's kernel sum over the plateau %.3f, its velocity (%.3f, %.3f) sqrt(g H)\n",
          slab, params.viscosity,
          20.0 * params.viscosity / (kRestDensity * sqrt(params.stiffness) * kernel_radius(step)),
          window_mean(sim_t, side_p, frames, 3.3, 4.5), window_mean(sim_t, wall_fill, frames, 3.3, 4.5),
          window_mean(sim_t, wall_u, frames, 3.3, 4.5), window_mean(sim_t, wall_v, frames, 3.3, 4.5));
  }
  {
    /* the series of the lattice as built (an ensemble's other draws would overwrite it) */
    FILE* out = seed ? NULL
                     : validation_open_output(features ? "dam_break_pressure_diffusion.csv"
                                                       : "dam_break_pressure.csv");
    if (out) {
      fprintf(out, "t_star,p_star\n");
      for (int i = 0; i < frames; ++i) fprintf(out, "%.5f,%.5f\n", sim_t[i], sim_p[i]);
      fclose(out);
    }
  }
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
  {
    /* an impact never seen reads as 100 % late */
    reading result = {t_sim > 0.0 ? t_sim / t_data - 1.0 : 1.0, plateau_sim / plateau_data - 1.0};
    return result;
  }
}

/* The bounds: the impact's (impact_bound()), and with `plateau` the plateau's, the 20 %. */
static void check(reading r, int plateau) {
  assert_true(fabs(r.impact) <= impact_bound() || measuring());
  assert_true(!plateau || fabs(r.plateau) <= 0.2 || measuring());
}

static const uint32_t kDiffusion = SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION;

static void test_plain_impact(void** state) {
  (void)state;
  check(dam_break_pressure(SPH_FEATURE_NONE, "plain", 0, 0), 0);
}

static void test_diffusion_impact(void** state) {
  (void)state;
  check(dam_break_pressure(kDiffusion, "diffusion", 0, 0), 0);
}

static void test_plain(void** state) {
  (void)state;
  check(dam_break_pressure(SPH_FEATURE_NONE, "plain", 1, 0), 1);
}

static void test_diffusion(void** state) {
  (void)state;
  check(dam_break_pressure(kDiffusion, "diffusion", 1, 0), 1);
}

/* The bounds on the mean of an ensemble (DAM_PRESSURE_ENSEMBLE draws, default 6: the
 * lattice as built and seeds 1-5): one draw's impact scatters by several percent under
 * rounding-sized moves of the lattice (docs/validation.md), so one draw passing or failing says
 * little. The impact within 5 %, the plateau within 20 %, both of the ensemble's mean. */
static void ensemble(uint32_t features, const char* name) {
  const int draws = getenv("DAM_PRESSURE_ENSEMBLE") ? atoi(getenv("DAM_PRESSURE_ENSEMBLE")) : 6;
  /* DAM_PRESSURE_FIRST_DRAW=k: the draws k .. k + draws - 1 (more draws of a measured ensemble, or
   * one draw a process to run them side by side) */
  const int first = getenv("DAM_PRESSURE_FIRST_DRAW") ? atoi(getenv("DAM_PRESSURE_FIRST_DRAW")) : 0;
  reading mean = {0.0, 0.0};
  double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
  assert_true(draws >= 1);
  for (int i = 0; i < draws; ++i) {
    const reading r = dam_break_pressure(features, name, 1, (uint64_t)(first + i));
    mean.impact += r.impact / draws;
    mean.plateau += r.plateau / draws;
    lo[0] = fmin(lo[0], r.impact), hi[0] = fmax(hi[0], r.impact);
    lo[1] = fmin(lo[1], r.plateau), hi[1] = fmax(hi[1], r.plateau);
  }
  print_message(
      "dam break pressure ensemble (%s, %d draws): impact mean %+.1f %% (draws %+.1f to %+.1f %%), "
      "plateau mean %+.1f %% (draws %+.1f to %+.1f %%)\n",
      name, draws, 100.0 * mean.impact, 100.0 * lo[0], 100.0 * hi[0], 100.0 * mean.plateau, 100.0 * lo[1],
      100.0 * hi[1]);
  assert_true(fabs(mean.impact) <= 0.05 || measuring());
  assert_true(fabs(mean.plateau) <= 0.2 || measuring());
}

static void test_plain_ensemble(void** state) {
  (void)state;
  ensemble(SPH_FEATURE_NONE, "plain");
}

static void test_diffusion_ensemble(void** state) {
  (void)state;
  ensemble(kDiffusion, "diffusion");
}

/* Each case is its own ctest (tests/validation/CMakeLists.txt): the impact cases run in CI with
 * the draws' spread as bound; the plain ensemble (the bounds on the mean) is too long for
 * CI and runs from scripts/validate, as the diffusion's (test_diffusion_ensemble) does
 * (docs/validation.md, "Dam break: the wall-pressure sensor"). */
int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plain_impact),   cmocka_unit_test(test_diffusion_impact),
      cmocka_unit_test(test_plain),          cmocka_unit_test(test_diffusion),
      cmocka_unit_test(test_plain_ensemble), cmocka_unit_test(test_diffusion_ensemble),
  };
  /* With names, those cases; a name that is no case is an error (exit 2), not a run of none. */
  return capi_run_named_cases("dam_break_pressure", tests, sizeof tests / sizeof tests[0], argc, argv);
}
