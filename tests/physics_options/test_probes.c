// SPDX-License-Identifier: MIT
/* Probes and gauges (sph_probe_*; src/physics/probe_sampling.h), against what they must read.
 * Lattice step 1 cm (spacing 1.41 cm, h = 2.5 cm), ideal gas k = 100 (the defaults).
 *   - brute force: after a sloshing start, one step of a single substep; the probe's sample is
 *     the interpolant over the state that substep started from (the positions and velocities
 *     read before the step, the densities and pressures of its density pass read after it),
 *     evaluated here in double over every particle: within 1e-4 relative (float sums of ~100
 *     terms against double; measured below 1e-5), a gauge's column integral likewise;
 *   - a resting tank: the pressure difference of two probes against rho0 g (d2 - d1); with the
 *     walls in the density, each probe's pressure against the weight of the water above it per
 *     unit area (bounds and why at the test);
 *   - a body of water moving at a uniform velocity without gravity: a probe it passes reads that
 *     velocity and rho0, a gauge through it the block's height (its fill height);
 *   - sampling: EVERY_SUBSTEP averages the step's substeps, EVERY_FRAME reads the last; a
 *     checkpoint carries the probes (a restore and a load);
 *   - bad input: each field named, the world unchanged (no slot taken), handles checked.
 * PROBES_MEASURE=1 prints the measurements without asserting the bounds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_scenes.h"

static const double kStep = 0.01; /* support_fcc_box's step; the world's spacing is step sqrt 2 */
static const double kGravity = 9.81;
static const double kPi = 3.14159265358979323846;

static int measuring(void) { return getenv("PROBES_MEASURE") != NULL; }
/* The resting tank's absolute pressure with the walls in the density, against the weight above:
 * the 1 % under PROBES_STRICT=1 (physics_probes_strict_KNOWN_ISSUE), otherwise 2.5 %. Over
 * 1.6 s the CI's draw reads -0.91 to -1.20 % on the CPU; 19 draws of the same settling (tank
 * voxels 0.25-0.6 steps, lattice nudges of 1e-7 to 1e-6 m, dt_max a little off) read -0.40 to
 * -2.63 %, mean -1.40 %, no draw with all four probes within 1 % (docs/validation.md, "The resting
 * tank's probes against the weight above"): the bound is not held, and 2.5 % is the bound
 * kept from the reference before (not widened; two of the 19 draws leave it, by 0.01 and 0.13 %). */
static double absolute_bound(void) { return getenv("PROBES_STRICT") ? 0.01 : 0.025; }

static sph_world_def probe_world_def(uint32_t capacity) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = (float)(kStep * sqrt(2.0));
  def.capacity = capacity;
  return def;
}

static sph_probe_id add_point(sph_world* world, double x, double y, double z, sph_probe_sampling sampling) {
  sph_probe_def def;
  sph_probe_id id = {0};
  EXPECT_OK(sph_probe_def_init(&def));
  def.position.x = (float)x, def.position.y = (float)y, def.position.z = (float)z;
  def.sampling = sampling;
  EXPECT_OK(sph_probe_create(world, &def, &id));
  return id;
}

/* A vertical gauge (up: against gravity) from (x, y0, z), `length` long. */
static sph_probe_id add_gauge(sph_world* world, double x, double y0, double z, double length,
                              double spacing) {
  sph_probe_def def;
  sph_probe_id id = {0};
  EXPECT_OK(sph_probe_def_init(&def));
  def.kind = SPH_PROBE_GAUGE;
  def.position.x = (float)x, def.position.y = (float)y0, def.position.z = (float)z;
  def.length = (float)length;
  def.sample_spacing = (float)spacing;
  EXPECT_OK(sph_probe_create(world, &def, &id));
  return id;
}

static sph_probe_reading reading_of(const sph_world* world, sph_probe_id id) {
  sph_probe_reading r;
  EXPECT_OK(sph_probe_reading_init(&r));
  EXPECT_OK(sph_probe_get_reading(world, id, &r));
  return r;
}

/* ---- brute force ---------------------------------------------------------------------------- */

/* W_poly6 (Mueller et al. 2003) in double. */
static double poly6(double r2, double h) {
  if (r2 >= h * h) return 0.0;
  return 315.0 / (64.0 * kPi * pow(h, 9.0)) * pow(h * h - r2, 3.0);
}

typedef struct brute_sums {
  double kernel, mass, pressure, velocity[3];
} brute_sums;

/* The interpolant's sums at x over n particles (positions and velocities of the substep's start,
 * densities and pressures of its density pass, all by particle id). */
static void brute_gather(const double x[3], uint32_t n, const float* pos, const float* vel, const float* rho,
                         const float* p, double mass, double h, brute_sums* s) {
  for (uint32_t j = 0; j < n; ++j) {
    const double dx = x[0] - pos[3 * j], dy = x[1] - pos[3 * j + 1], dz = x[2] - pos[3 * j + 2];
    const double w = poly6(dx * dx + dy * dy + dz * dz, h);
    const double vw = mass / rho[j] * w;
    s->kernel += vw;
    s->mass += mass * w;
    s->pressure += vw * p[j];
    for (int k = 0; k < 3; ++k) s->velocity[k] += vw * vel[3 * j + k];
  }
}

/* Copies an attribute and re-orders it by particle id (ids are 0..n-1 here). */
static float* by_id(const sph_world* world, sph_attribute attribute, int components, uint32_t* count) {
  float* raw = NULL;
  uint32_t* ids = NULL;
  uint32_t n = 0, m = 0;
  float* out;
  EXPECT_OK(support_copy(world, attribute, (void**)&raw, &n));
  EXPECT_OK(support_copy(world, SPH_ATTRIBUTE_ID, (void**)&ids, &m));
  assert_int_equal(n, m);
  out = (float*)malloc(sizeof(float) * components * (n ? n : 1));
  assert_non_null(out);
  for (uint32_t i = 0; i < n; ++i) {
    assert_true(ids[i] < n);
    memcpy(out + (size_t)components * ids[i], raw + (size_t)components * i, sizeof(float) * components);
  }
  free(raw);
  free(ids);
  *count = n;
  return out;
}

static double relative(double got, double want, double scale) { return fabs(got - want) / scale; }

static void test_brute_force(void** state) {
  const support_water_tank water = {{8, 12, 8}, kStep, {0.0, 0.0, 0.0}, {0.16, 0.24, 0.08}, 0.0f};
  const sph_world_def def = probe_world_def(0);
  float *pos, *vel, *rho, *p;
  uint32_t count = 0;
  support_world w;
  sph_sdf* sdf = NULL;
  sph_probe_id points[3], gauge;
  const double where[3][3] = {{0.04, 0.03, 0.04}, {0.02, 0.06, 0.03}, {0.10, 0.01, 0.04}};
  double worst = 0.0, h, mass;
  sph_stats stats;
  (void)state;
  EXPECT_OK(support_water_tank_open(&w, sph_test_backend(), &def, NULL, &water, &sdf, NULL, NULL));
  h = w.def.kernel_radius;
  mass = w.mass;
  for (int k = 0; k < 3; ++k)
    points[k] = add_point(w.world, where[k][0], where[k][1], where[k][2], SPH_PROBE_EVERY_FRAME);
  gauge = add_gauge(w.world, 0.05, -0.03, 0.04, 0.25, 0.0);
  /* The column collapses: a flow with velocity and pressure gradients. */
  for (int frame = 0; frame < 8; ++frame) EXPECT_OK(sph_world_step(w.world, 0.02f));
  pos = by_id(w.world, SPH_ATTRIBUTE_POSITION, 3, &count);
  vel = by_id(w.world, SPH_ATTRIBUTE_VELOCITY, 3, &count);
  /* One substep: a frame shorter than any step the controller picks. */
  EXPECT_OK(sph_world_step(w.world, 1e-5f));
  EXPECT_OK(sph_stats_init(&stats));
  EXPECT_OK(sph_world_get_stats(w.world, &stats));
  assert_int_equal(stats.substeps, 1);
  rho = by_id(w.world, SPH_ATTRIBUTE_DENSITY, 1, &count);
  p = by_id(w.world, SPH_ATTRIBUTE_PRESSURE, 1, &count);
  for (int k = 0; k < 3; ++k) {
    const sph_probe_reading r = reading_of(w.world, points[k]);
    brute_sums s = {0.0, 0.0, 0.0, {0.0, 0.0, 0.0}};
    double e[6];
    const double pressure_scale = w.def.rest_density * kGravity * 0.12; /* rho0 g H of the column */
    brute_gather(where[k], count, pos, vel, rho, p, mass, h, &s);
    assert_true(s.kernel > 0.1); /* the points are in the water */
    assert_int_equal(r.samples, 1);
    e[0] = relative(r.kernel_sum, s.kernel, 1.0);
    e[1] = relative(r.density, s.mass / s.kernel, w.def.rest_density);
    e[2] = relative(r.pressure, s.pressure / s.kernel, pressure_scale);
    for (int c = 0; c < 3; ++c) e[3 + c] = relative((&r.velocity.x)[c], s.velocity[c] / s.kernel, 1.0);
    for (int c = 0; c < 6; ++c) worst = e[c] > worst ? e[c] : worst;
    print_message(
        "probe %d: kernel sum %.6f (brute %.6f), density %.3f (%.3f), pressure %.3f (%.3f), "
        "v_y %.5f (%.5f)\n",
        k, r.kernel_sum, s.kernel, r.density, s.mass / s.kernel, r.pressure, s.pressure / s.kernel,
        r.velocity.y, s.velocity[1] / s.kernel);
  }
  {
    /* The gauge: the midpoint rule over the same points, 0.25 m / (h / 8) steps, of sum m W / rho0. */
    const sph_probe_reading r = reading_of(w.world, gauge);
    const uint32_t steps = (uint32_t)ceil(0.25 / ((float)h / 8.0f));
    const double dz = 0.25 / steps;
    double height = 0.0;
    for (uint32_t q = 0; q < steps; ++q) {
      const double x[3] = {0.05, -0.03 + (q + 0.5) * dz, 0.04};
      brute_sums s = {0.0, 0.0, 0.0, {0.0, 0.0, 0.0}};
      brute_gather(x, count, pos, vel, rho, p, mass, h, &s);
      height += s.mass * dz / w.def.rest_density;
    }
    print_message("gauge: water height %.6f m (brute force %.6f m)\n", r.water_height, height);
    worst = fmax(worst, relative(r.water_height, height, height));
  }
  print_message("brute force: worst relative difference %.2e (bound 1e-4)\n", worst);
  assert_true(worst <= 1e-4 || measuring());
  free(pos);
  free(vel);
  free(rho);
  free(p);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

/* ---- a resting tank ------------------------------------------------------------------------- */

/* PROBES_SCAN=1 (measurement only, with PROBES_MEASURE=1): point probes on the centre line every
 * quarter step from 1 to 23 cm, each against the weight above its height (as the test's probes)
 * and against the old reference, the resting compressible column below the gauge's level (wt-place's
 * scan, commit 7f6655d). */
#define SCAN_PROBES 89
static int scanning(void) { return getenv("PROBES_SCAN") != NULL; }
static double scan_height(int i) { return 0.01 + 0.0025 * i; }

/* The resting compressible column's pressure at y (the reference before the weight above): with
 * p = k (rho - rho0) and dp/dd = rho g, p(y) = k rho0 ((1 + a H) e^(-a (y - f)) - 1), a = g / k, H the
 * gauge's water height and f the film the walls' calibration keeps free of water at the floor. */
static double column_pressure(double k, double rho0, double height, double y) {
  const double a = kGravity / k;
  return k * rho0 * ((1.0 + a * height) * exp(-a * (y - CAPI_RESTING_FILM)) - 1.0);
}

/* PROBES_STRESS=1 (measurement only, with PROBES_MEASURE=1): the pressure force's momentum flux
 * through a horizontal plane at each probe's height, over the tank's middle (the pairs whose segment
 * crosses the plane within 3 cm of the centre line in x and z, more than h from the side walls):
 * sum over pairs i above, j below of m^2 (p_i / rho_i^2 + p_j / rho_j^2) |grad W_spiky| (y_i - y_j) / r
 * per unit area (pressure_force.h, Monaghan's form), from each frame's particles. In a resting tank
 * it is what holds the water above up, so it equals the weight above; against the probes' pressure
 * it gives the ratio of the discrete stress to the interpolated pressure. Also the mean of
 * -sum_j (m / rho_j) (y_i - y_j) dW_spiky/dy_i over the middle's particles between 3 and 20 cm (1 in
 * the continuum; both with the world's lattice-scaled W_spiky). flux[n + k]: the whole plane's, N. */
static int stressing(void) { return getenv("PROBES_STRESS") != NULL; }

static void stress_frame(const sph_world* world, double h, double mass, const double* heights, int n,
                         double* flux, double* gamma, double* gamma_count) {
  const double c = CAPI_RESTING_WIDTH / 2, half = 0.03, grad = -45.0 / (kPi * pow(h, 6.0));
  /* The world's W_spiky is scaled so that the FCC lattice's gradient moment is 1 (fcc_spiky_scale:
   * sum W_poly6 over sum x^2 |dW_spiky/dr| / r on the lattice at step 1 cm). */
  double w_sum = 0.0, moment = 0.0, scale;
  for (int a = -3; a <= 3; ++a)
    for (int b = -3; b <= 3; ++b)
      for (int e = -3; e <= 3; ++e) {
        const double r2 = (a * a + b * b + e * e) * kStep * kStep, r = sqrt(r2);
        if (((a + b + e) & 1) || r >= h) continue;
        w_sum += poly6(r2, h);
        if (r > 0.0) moment += -grad * (h - r) * (h - r) * (a * kStep) * (a * kStep) / r;
      }
  scale = w_sum / moment;
  uint32_t count = 0;
  float *x, *rho, *p;
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  x = (float*)malloc(sizeof(float) * 3 * count);
  rho = (float*)malloc(sizeof(float) * count);
  p = (float*)malloc(sizeof(float) * count);
  assert_non_null(x);
  assert_non_null(rho);
  assert_non_null(p);
  EXPECT_OK(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, x, sizeof(float) * 3 * count, 0, 0, count,
                                     NULL));
  EXPECT_OK(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, rho, sizeof(float) * count, 0, 0, count, NULL));
  EXPECT_OK(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_PRESSURE, p, sizeof(float) * count, 0, 0, count, NULL));
  for (uint32_t i = 0; i < count; ++i) {
    const int middle = fabs(x[3 * i] - c) < half && fabs(x[3 * i + 2] - c) < half && x[3 * i + 1] > 0.03 &&
                       x[3 * i + 1] < 0.20;
    double g = 0.0;
    for (uint32_t j = 0; j < count; ++j) {
      const double dx = x[3 * i] - x[3 * j], dy = x[3 * i + 1] - x[3 * j + 1],
                   dz = x[3 * i + 2] - x[3 * j + 2];
      const double r = sqrt(dx * dx + dy * dy + dz * dz);
      double dw;
      if (j == i || r >= h) continue;
      dw = grad * (h - r) * (h - r) / r; /* grad W = dw (x_i - x_j) */
      if (middle) g -= scale * mass / rho[j] * dy * dw * dy;
      if (dy <= 0.0) continue;
      for (int k = 0; k < n; ++k) {
        const double t = (x[3 * i + 1] - heights[k]) / dy; /* i above the plane, j below: 0 < t < 1 */
        if (x[3 * i + 1] <= heights[k] || x[3 * j + 1] >= heights[k]) continue;
        const double f = -scale * mass * mass *
                         (p[i] / ((double)rho[i] * rho[i]) + p[j] / ((double)rho[j] * rho[j])) * dw * dy;
        flux[n + k] += f;
        if (fabs(x[3 * i] - t * dx - c) >= half || fabs(x[3 * i + 2] - t * dz - c) >= half) continue;
        flux[k] += f;
      }
    }
    if (middle) {
      *gamma += g;
      *gamma_count += 1.0;
    }
  }
  free(x);
  free(rho);
  free(p);
}

/* Water 12 x 24 x 12 layers (12 cm wide, H = 24 cm deep) settled in a closed tank for 1.2 s (the
 * acoustic step limit; the default viscosity damps the start-up waves), then read over 1.6 s:
 * a gauge through the centre from 3 cm below the floor to 0.45 m, point probes on the centre line
 * at y = 4, 8, 12 and 16 cm, every substep averaged (capi_resting_tank_open), and with the walls in
 * the density the water's weight above each probe (capi_count_above, each frame's positions).
 * PROBES_DT_MAX (s; measurement only): dt_max, a draw of the same settling. */
static void resting_tank(uint32_t features) {
  const double width = CAPI_RESTING_WIDTH;
  const double* heights = capi_resting_heights;
  capi_resting_tank t;
  support_world* w = &t.w;
  sph_world_def def = probe_world_def(0);
  sph_world_params params;
  sph_probe_id snapshot, columns[4], scan[SCAN_PROBES];
  double snapshot_sum = 0.0, snapshot_sum2 = 0.0;
  int snapshots = 0, frames = 0;
  double pressure[4] = {0.0, 0.0, 0.0, 0.0}, height = 0.0, time = 0.0, probe_time = 0.0, fill, rho0;
  double above[4] = {0.0, 0.0, 0.0, 0.0}, above_slab[4] = {0.0, 0.0, 0.0, 0.0};
  double column_height[4] = {0.0, 0.0, 0.0, 0.0}, column_time = 0.0, floor_above = 0.0;
  double scan_y[SCAN_PROBES], scan_p[SCAN_PROBES], scan_above[SCAN_PROBES], scan_time = 0.0;
  double flux[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, gamma = 0.0, gamma_count = 0.0;
  sph_probe_id across[12];
  double across_height[12];
  const int weighing = (features & SPH_FEATURE_BOUNDARY_DENSITY) != 0;
  const int scan_on = weighing && scanning();
  def.features = features;
  sph_world_params_init(&params);
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  if (getenv("PROBES_DT_MAX")) params.dt_max = (float)atof(getenv("PROBES_DT_MAX"));
  capi_resting_tank_open(&t, &def, &params, SPH_PROBE_EVERY_FRAME);
  rho0 = w->def.rest_density;
  /* One substep's pressure per frame at 8 cm: its spread over time is the solver's pressure noise
   * (reported for the density diffusion of issue 17 item 3 to compare against). */
  snapshot = add_point(w->world, width / 2, heights[1], width / 2, SPH_PROBE_EVERY_FRAME);
  /* Measuring: a gauge up the centre line from each probe, the interpolant's own column above it
   * there (rho0 g times its water height: the weight above at the centre, no area). */
  for (int k = 0; weighing && measuring() && k < 4; ++k)
    columns[k] = add_gauge(w->world, width / 2, heights[k], width / 2, 0.45 - heights[k], 0.0);
  for (int i = 0; i < SCAN_PROBES; ++i) {
    scan_y[i] = scan_height(i);
    scan_p[i] = scan_above[i] = 0.0;
    if (scan_on) scan[i] = add_point(w->world, width / 2, scan_y[i], width / 2, SPH_PROBE_EVERY_SUBSTEP);
  }
  /* Scanning: the water's mass per unit area across the tank, gauges at x = 0.5 ... 6 cm (z central). */
  for (int i = 0; i < 12; ++i) {
    across_height[i] = 0.0;
    if (scan_on) across[i] = add_gauge(w->world, 0.005 * (i + 1), -0.03, width / 2, 0.48, 0.0);
  }
  /* The window: 80 frames (1.6 s). The probes' mean over 0.4 s (20 frames) swung by about 1 % of
   * rho0 g d between draws of the same settling (CPU -0.19 % and CUDA -1.93 % at 8 cm, the same
   * code): the tank's sloshing has periods of tenths of a second, so 0.4 s held too few of them
   * for the 1 % bound. PROBES_WINDOW=N (frames) measures another window. */
  const int window = getenv("PROBES_WINDOW") ? atoi(getenv("PROBES_WINDOW")) : 80;
  for (int frame = 0; frame < 60 + window; ++frame) {
    EXPECT_OK(sph_world_step(w->world, 0.02f));
    if (frame < 60) continue;
    {
      const sph_probe_reading g = reading_of(w->world, t.gauge);
      const sph_probe_reading one = reading_of(w->world, snapshot);
      snapshot_sum += one.pressure;
      snapshot_sum2 += (double)one.pressure * one.pressure;
      ++snapshots;
      height += g.water_height * g.time;
      time += g.time;
      for (int k = 0; k < 4; ++k) {
        const sph_probe_reading r = reading_of(w->world, t.probes[k]);
        assert_true(r.samples >= 1);
        pressure[k] += r.pressure * r.time;
        if (k == 0) probe_time += r.time;
      }
    }
    if (weighing) {
      const double below_floor = -0.05;
      capi_count_above(w->world, w->def.kernel_radius, heights, 4, above, above_slab);
      capi_count_above(w->world, w->def.kernel_radius, &below_floor, 1, &floor_above, NULL);
      if (measuring() && stressing())
        stress_frame(w->world, w->def.kernel_radius, w->mass, heights, 4, flux, &gamma, &gamma_count);
      ++frames;
    }
    for (int k = 0; weighing && measuring() && k < 4; ++k) {
      const sph_probe_reading c = reading_of(w->world, columns[k]);
      column_height[k] += c.water_height * c.time;
      if (k == 0) column_time += c.time;
    }
    if (scan_on) {
      for (int i = 0; i < SCAN_PROBES; ++i) {
        const sph_probe_reading r = reading_of(w->world, scan[i]);
        scan_p[i] += r.pressure * r.time;
        if (i == 0) scan_time += r.time;
      }
      capi_count_above(w->world, w->def.kernel_radius, scan_y, SCAN_PROBES, scan_above, NULL);
      for (int i = 0; i < 12; ++i) across_height[i] += reading_of(w->world, across[i]).water_height;
    }
  }
  height /= time;
  for (int k = 0; k < 4; ++k) pressure[k] /= probe_time;
  {
    sph_stats st;
    EXPECT_OK(sph_stats_init(&st));
    EXPECT_OK(sph_world_get_stats(w->world, &st));
    print_message("  particles: density min %.2f mean %.2f max %.2f, max speed %.4f m/s, k = %.1f\n",
                  st.density_min, st.density_mean, st.density_max, st.max_speed, w->params.stiffness);
  }
  /* The fill height: the particles' volume at rest density over the tank's floor. */
  fill = t.count * (double)w->mass / rho0 / (width * width);
  print_message("resting tank: gauge height %.5f m, fill height %.5f m (%+.2f %%)\n", height, fill,
                100.0 * (height / fill - 1.0));
  for (int k = 0; k < 4; ++k) {
    const double d = height - heights[k];
    print_message(
        "  probe at y = %.2f m: p = %.2f Pa, rho0 g d = %.2f Pa (d = %.4f m below the gauge's "
        "surface; %+.2f %%)\n",
        heights[k], pressure[k], rho0 * kGravity * d, d, 100.0 * (pressure[k] / (rho0 * kGravity * d) - 1.0));
  }
  {
    const double mean = snapshot_sum / snapshots;
    print_message(
        "  pressure noise at 8 cm (one substep per frame, %d frames): mean %.1f Pa, standard deviation "
        "%.1f Pa (%.1f %% of the mean; k = %.0f, no density diffusion)\n",
        snapshots, mean, sqrt(fmax(0.0, snapshot_sum2 / snapshots - mean * mean)),
        100.0 * sqrt(fmax(0.0, snapshot_sum2 / snapshots - mean * mean)) / mean, w->params.stiffness);
  }
  {
    const double gradient = (pressure[0] - pressure[3]) / (heights[3] - heights[0]);
    print_message("  (p(4 cm) - p(16 cm)) / 12 cm = %.2f Pa/m against rho0 g = %.2f Pa/m (%+.2f %%)\n",
                  gradient, rho0 * kGravity, 100.0 * (gradient / (rho0 * kGravity) - 1.0));
    /* Without the walls in the density: the pressure gradient within 1 % of rho0 g (the issue's
     * bound for a probe's pressure; measured -0.10 % over 1.6 s), and the absolute pressure only printed:
     * it reads a near constant 95 Pa below rho0 g d (-7 % at 14 cm, -44 % at 2 cm). That is the
     * tank's walls, not the probe: the particles within h of the walls read low densities and
     * pack tighter, the middle of the tank stands 24 % below n m / (rho0 A) and its pressure does
     * not follow its own column. With the walls in the density (the second case) the same
     * probes read within 0.4-2.6 % of the weight of the water above them, so neither the
     * interpolant, nor its Shepard normalisation, nor the clamped equation of state's zero at the
     * surface is the cause. */
    if (features == SPH_FEATURE_NONE)
      assert_true(fabs(gradient / (rho0 * kGravity) - 1.0) <= 0.01 || measuring());
  }
  if (weighing) {
    /* The absolute pressure against the weight of the water above each probe per unit area: in a
     * resting tank with vertical frictionless walls the pressure at a height is exactly that
     * (hydrostatics, whatever the compression), so it needs neither the gauge's level nor where
     * the floor is. The particles above are counted by the interpolant's own column
     * (capi_count_above), the area is the water's (capi_resting_water_area: the tank's less the
     * films its walls keep). Before it the reference was the resting compressible column below the
     * gauge's level (printed under PROBES_MEASURE=1), which read the probes -0.77 to -0.94 % (CPU)
     * and -1.32 to -1.82 % (H200) of rho0 g d; the weight above reads them about 0.55 % lower, as
     * the centre's column holds a little less water than the mean over the area. */
    const double k = w->params.stiffness, area = capi_resting_water_area();
    const double weight = kGravity * w->mass / area; /* Pa per particle above */
    const double total = weight * floor_above / frames;
    print_message(
        "  the water's weight over its area (%.5f m)^2: %.2f Pa = rho0 g %.5f m (the gauge's "
        "%.5f m, %+.3f %%); over the tank's (%.2f m)^2 rho0 g %.5f m (%+.3f %%)\n",
        sqrt(area), total, total / (rho0 * kGravity), height,
        100.0 * (height * rho0 * kGravity / total - 1.0), width, fill, 100.0 * (height / fill - 1.0));
    for (int j = 0; j < 4; ++j) {
      const double want = weight * above[j] / frames, slab = weight * above_slab[j] / frames;
      const double old = column_pressure(k, rho0, height, heights[j]);
      const double d_old = CAPI_RESTING_FILM + log1p(kGravity / k * height) / (kGravity / k) - heights[j];
      print_message(
          "  probe at y = %.2f m: p = %.2f Pa, the weight above %.2f Pa (%+.2f %%; as slabs %.2f Pa, "
          "%+.2f %%; over the tank's area %+.2f %%)\n",
          heights[j], pressure[j], want, 100.0 * (pressure[j] / want - 1.0), slab,
          100.0 * (pressure[j] / slab - 1.0), 100.0 * (pressure[j] / (want * area / (width * width)) - 1.0));
      if (measuring() && stressing())
        print_message(
            "    the pressure force's flux through the plane over the middle: %.2f Pa (the probe %+.2f %%, "
            "the "
            "weight above %+.2f %%); through the whole plane %.4f N (the weight above %.4f N, %+.2f %%)\n",
            flux[j] / frames / (0.06 * 0.06),
            100.0 * (pressure[j] / (flux[j] / frames / (0.06 * 0.06)) - 1.0),
            100.0 * (flux[j] / frames / (0.06 * 0.06) / want - 1.0), flux[4 + j] / frames, want * area,
            100.0 * (flux[4 + j] / frames / (want * area) - 1.0));
      if (measuring()) {
        const double centre = rho0 * kGravity * column_height[j] / column_time;
        print_message(
            "    the centre's column above (a gauge from the probe up): %.2f Pa (%+.2f %%); the old "
            "reference, the compressible column below the gauge's level: %.2f Pa (%+.2f %% of rho0 g d, "
            "d = %.4f m)\n",
            centre, 100.0 * (pressure[j] / centre - 1.0), old,
            100.0 * (pressure[j] - old) / (rho0 * kGravity * d_old), d_old);
      }
      /* absolute_bound() of the weight above, at depths of 8-20 cm (3-8 h: below the diffuse
       * surface layer, the top h, where a kernel reaches into air). Why not 1 % (PROBES_STRESS):
       * the pressure force carries the weight above through the whole plane within 0.9 %, but over
       * the tank's middle it carries 0.5-10 % more than the mean, and there the settled packing's
       * gradient moment is 1.022 (1 on the lattice the kernel is scaled on), so the interpolated
       * pressure is not the stress at the percent level. */
      assert_true(fabs(pressure[j] / want - 1.0) <= absolute_bound() || measuring());
    }
    if (measuring() && stressing())
      print_message("  the middle's -sum_j V_j (y_i - y_j) dW/dy_i: %.5f (%.0f particle frames)\n",
                    gamma / gamma_count, gamma_count);
    for (int i = 0; scan_on && i < 12; ++i)
      print_message("across x %.3f m: water height %.5f m (%+.3f %% of the water's mass over its area)\n",
                    0.005 * (i + 1), across_height[i] / frames,
                    100.0 * (across_height[i] / frames * rho0 * kGravity / total - 1.0));
    for (int i = 0; scan_on && i < SCAN_PROBES; ++i) {
      const double p = scan_p[i] / scan_time, want = weight * scan_above[i] / frames;
      const double old = column_pressure(k, rho0, height, scan_y[i]);
      print_message("scan y %.4f p %.3f weight above %.3f (%+.3f %%) old column %.3f (%+.3f %%)\n", scan_y[i],
                    p, want, 100.0 * (p / want - 1.0), old, 100.0 * (p / old - 1.0));
    }
  }
  capi_resting_tank_close(&t);
}

static void test_resting_tank(void** state) {
  (void)state;
  resting_tank(SPH_FEATURE_NONE);
}

static void test_resting_tank_walls_in_density(void** state) {
  (void)state;
  resting_tank(SPH_FEATURE_BOUNDARY_DENSITY);
}

/* ---- a uniform flow ------------------------------------------------------------------------- */

/* A block of 10 x 10 x 10 layers moving at U = (0.5, 0, 0.2) m/s without gravity, through a
 * probe fixed where the block's centre is after 0.1 s. The velocity field is uniform: a probe
 * must read U (within 1 % of |U|: the free surface's pressure pulls the outer layers inwards, by
 * symmetry not at the centre) and the rest density (within 1 %: the lattice is at rest density in
 * its interior by construction of the particle mass). */
static void test_uniform_flow(void** state) {
  const uint32_t layers[3] = {10, 10, 10};
  const float u[3] = {0.5f, 0.0f, 0.2f};
  float *lattice = NULL, *velocities;
  uint32_t n = 0;
  support_world w;
  sph_world_def def;
  sph_world_params params;
  sph_probe_id probe, gauge;
  sph_probe_reading r, g;
  double speed, error;
  (void)state;
  assert_int_equal(support_fcc_box(layers, kStep, NULL, &lattice, &n), SPH_OK);
  velocities = (float*)malloc(sizeof(float) * 3 * n);
  assert_non_null(velocities);
  for (uint32_t i = 0; i < n; ++i) memcpy(velocities + 3 * i, u, sizeof u);
  def = probe_world_def(n);
  EXPECT_OK(support_params_gravity_and_steps(&params, 0.0f, 0.0f, 0.0f, 1e-6f, 2e-3f));
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, &params));
  EXPECT_OK(support_spawn(w.world, lattice, velocities, n));
  free(lattice);
  free(velocities);
  probe = add_point(w.world, 0.05 + 0.1 * u[0], 0.05 + 0.1 * u[1], 0.05 + 0.1 * u[2], SPH_PROBE_EVERY_FRAME);
  gauge = add_gauge(w.world, 0.05 + 0.1 * u[0], -0.05, 0.05 + 0.1 * u[2], 0.2, 0.0);
  for (int frame = 0; frame < 5; ++frame) EXPECT_OK(sph_world_step(w.world, 0.02f));
  r = reading_of(w.world, probe);
  speed = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  error =
      sqrt(pow(r.velocity.x - u[0], 2) + pow(r.velocity.y - u[1], 2) + pow(r.velocity.z - u[2], 2)) / speed;
  print_message(
      "uniform flow: probe reads v = (%.5f, %.5f, %.5f), U = (%.2f, %.2f, %.2f): %.2e of |U|; "
      "density %.2f (rho0 %.2f), kernel sum %.4f\n",
      r.velocity.x, r.velocity.y, r.velocity.z, u[0], u[1], u[2], error, r.density, w.def.rest_density,
      r.kernel_sum);
  g = reading_of(w.world, gauge);
  print_message("uniform flow: a gauge through the block reads %.5f m of its 0.10000 m (%+.2f %%)\n",
                g.water_height, 100.0 * (g.water_height / 0.1 - 1.0));
  /* The gauge: the block's 10 layers are 0.1 m of water at rest density (support_fcc_box tiles
   * the box with the lattice's volume per point); within 1 %: the poly6 column integral's
   * quadrature error on the lattice is 0.13 % (probe_sampling.h), the rest is the block's
   * surface layers relaxing over the 0.1 s. */
  assert_true((error <= 0.01 && fabs(r.density / w.def.rest_density - 1.0) <= 0.01 &&
               fabs(g.water_height / 0.1 - 1.0) <= 0.01) ||
              measuring());
  EXPECT_OK(support_world_close(&w));
}

/* ---- sampling ------------------------------------------------------------------------------- */

/* EVERY_SUBSTEP: one sample per substep, the span the step's time; EVERY_FRAME: one sample, the
 * span its substep's. A probe in air reads zeros and a kernel sum of 0. */
static void test_sampling(void** state) {
  const uint32_t layers[3] = {6, 6, 6};
  float* lattice = NULL;
  uint32_t n = 0;
  support_world w;
  sph_world_def def;
  sph_probe_id every, last, air;
  sph_probe_reading a, b, c;
  sph_stats stats;
  (void)state;
  assert_int_equal(support_fcc_box(layers, kStep, NULL, &lattice, &n), SPH_OK);
  def = probe_world_def(n);
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(support_spawn(w.world, lattice, NULL, n));
  free(lattice);
  every = add_point(w.world, 0.03, 0.03, 0.03, SPH_PROBE_EVERY_SUBSTEP);
  last = add_point(w.world, 0.03, 0.03, 0.03, SPH_PROBE_EVERY_FRAME);
  air = add_point(w.world, 1.0, 1.0, 1.0, SPH_PROBE_EVERY_FRAME);
  a = reading_of(w.world, every);
  assert_int_equal(a.samples, 0); /* before the first step */
  EXPECT_OK(sph_world_step(w.world, 0.02f));
  EXPECT_OK(sph_stats_init(&stats));
  EXPECT_OK(sph_world_get_stats(w.world, &stats));
  a = reading_of(w.world, every);
  b = reading_of(w.world, last);
  c = reading_of(w.world, air);
  assert_true(stats.substeps > 1);
  assert_int_equal(a.samples, stats.substeps);
  assert_true(fabs(a.time - stats.frame_time) <= 1e-6 * stats.frame_time);
  assert_int_equal(b.samples, 1);
  assert_true(b.time > 0.0 && b.time < a.time);
  assert_true(a.pressure_max >= a.pressure);
  assert_true(b.kernel_sum > 0.5);
  assert_true(c.samples == 1 && c.kernel_sum == 0.0f && c.density == 0.0f && c.pressure == 0.0f);
  {
    /* Checkpoints carry the probes (format 6): a restore brings back the saved probes with their
     * ids (one removed after the save returns, one added after it is gone), their readings start
     * again; a world loaded from the checkpoint has them too and reads what the original reads. */
    uint64_t size = 0;
    void* saved;
    sph_world* loaded = NULL;
    sph_probe_id later;
    sph_probe_reading r;
    EXPECT_OK(sph_world_save(w.world, NULL, 0, &size));
    saved = malloc(size);
    assert_non_null(saved);
    EXPECT_OK(sph_world_save(w.world, saved, size, &size));
    EXPECT_OK(sph_world_step(w.world, 0.02f));
    EXPECT_OK(sph_probe_destroy(w.world, air));
    later = add_gauge(w.world, 0.03, -0.02, 0.03, 0.1, 0.0);
    EXPECT_OK(sph_world_restore(w.world, saved, size));
    EXPECT_OK(sph_probe_reading_init(&r));
    EXPECT_OK(sph_probe_get_reading(w.world, air, &r));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, NULL, sph_probe_get_reading(w.world, later, &r));
    EXPECT_OK(sph_world_load(w.context, saved, size, &loaded));
    free(saved);
    EXPECT_OK(sph_world_step(loaded, 0.02f));
    EXPECT_OK(sph_probe_get_reading(loaded, every, &r));
    a = reading_of(w.world, every);
    assert_int_equal(a.samples, 0);
    EXPECT_OK(sph_world_step(w.world, 0.02f));
    a = reading_of(w.world, every);
    assert_true(a.samples > 1 && a.kernel_sum > 0.5f);
    /* the same state, the same step: the same reading */
    assert_true(a.samples == r.samples && a.density == r.density && a.pressure == r.pressure &&
                a.kernel_sum == r.kernel_sum && a.time == r.time);
    EXPECT_OK(sph_world_destroy(loaded));
  }
  EXPECT_OK(support_world_close(&w));
}

/* ---- bad input ------------------------------------------------------------------------------ */

static void test_bad_input(void** state) {
  support_world w, dfsph;
  sph_world_def def;
  sph_probe_def good, bad;
  sph_probe_id id = {0}, untouched = {0x1234}, first, stale;
  sph_probe_reading r;
  (void)state;
  def = probe_world_def(64);
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(sph_probe_def_init(&good));
  good.kind = SPH_PROBE_GAUGE;
  good.length = 0.5f;

  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def", sph_probe_create(w.world, NULL, &id));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_id", sph_probe_create(w.world, &good, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_probe_create(NULL, &good, &id));
#define EXPECT_BAD(result, field, change)                              \
  do {                                                                 \
    bad = good;                                                        \
    change;                                                            \
    id = untouched;                                                    \
    EXPECT_ERROR(result, field, sph_probe_create(w.world, &bad, &id)); \
    assert_true(id.bits == untouched.bits);                            \
  } while (0)
  EXPECT_BAD(SPH_ERROR_UNSUPPORTED, "def->kind", bad.kind = (sph_probe_kind)7);
  EXPECT_BAD(SPH_ERROR_UNSUPPORTED, "def->sampling", bad.sampling = (sph_probe_sampling)2);
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->reserved0", bad.reserved0 = 1);
  EXPECT_BAD(SPH_ERROR_VERSION_MISMATCH, "def->struct_size", bad.struct_size = 8);
  for (int i = 0; i < CAPI_NON_FINITE_COUNT; ++i) {
    EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->position", bad.position.y = capi_non_finite(i));
    EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->direction", bad.direction.x = capi_non_finite(i));
    EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->length", bad.length = capi_non_finite(i));
    EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->sample_spacing", bad.sample_spacing = capi_non_finite(i));
  }
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->position", bad.position.x = 1e9f);
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->length", bad.length = 0.0f);
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->length", bad.length = -1.0f);
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->sample_spacing", bad.sample_spacing = -0.1f);
  EXPECT_BAD(SPH_ERROR_INVALID_ARGUMENT, "def->sample_spacing", bad.sample_spacing = 1e-6f);
#undef EXPECT_BAD
  /* A point reads only its position: the gauge's fields do not matter. */
  bad = good;
  bad.kind = SPH_PROBE_POINT;
  bad.length = -1.0f;
  EXPECT_OK(sph_probe_create(w.world, &bad, &first));
  /* No failed call took a slot: the first probe has the first id a world gives. */
  {
    support_world fresh;
    sph_probe_id other;
    EXPECT_OK(support_world_open(&fresh, sph_test_backend(), &def, NULL));
    EXPECT_OK(sph_probe_create(fresh.world, &good, &other));
    assert_true(other.bits == first.bits);
    EXPECT_OK(support_world_close(&fresh));
  }
  /* Handles: destroy, then the id is stale everywhere; {0} is a no-op for destroy. */
  stale = first;
  EXPECT_OK(sph_probe_destroy(w.world, first));
  EXPECT_OK(sph_probe_reading_init(&r));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_probe_get_reading(w.world, stale, &r));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_probe_destroy(w.world, stale));
  EXPECT_OK(sph_probe_destroy(w.world, (sph_probe_id){0}));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_probe_get_reading(w.world, (sph_probe_id){0}, &r));
  EXPECT_OK(sph_probe_create(w.world, &good, &id));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_probe_get_reading(w.world, id, NULL));
  /* A DFSPH world samples its probes too (test_dfsph_loads.c reads them). */
  def.solver = SPH_SOLVER_DFSPH;
  EXPECT_OK(support_world_open(&dfsph, sph_test_backend(), &def, NULL));
  EXPECT_OK(sph_probe_create(dfsph.world, &good, &id));
  EXPECT_OK(sph_probe_destroy(dfsph.world, id));
  EXPECT_OK(support_world_close(&dfsph));
  EXPECT_OK(support_world_close(&w));
}

/* All probes together sample at most 2^22 points a step (a point one, a gauge its samples): 64
 * gauges of 65536 samples fill it, one more probe of either kind is refused with CAPACITY, and
 * a removed gauge makes room again; a checkpoint at the limit loads. Before the limit, 65536
 * gauges of 65536 samples (each within its own bounds) counted 2^32 points, which wrapped to 0,
 * and the step wrote its samples into an empty buffer (a crash). */
static void test_point_budget(void** state) {
  support_world w;
  sph_world_def def;
  sph_probe_def gauge, point;
  sph_probe_id ids[64], extra = {0x1234}, id;
  uint64_t size = 0;
  void* saved;
  sph_world* loaded = NULL;
  int k;
  (void)state;
  def = probe_world_def(64);
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(sph_probe_def_init(&gauge));
  gauge.kind = SPH_PROBE_GAUGE;
  gauge.length = 1.0f;
  gauge.sample_spacing = 1.0f / 65536.0f; /* exactly 65536 steps, the most a gauge may have */
  EXPECT_OK(sph_probe_def_init(&point));
  for (k = 0; k < 64; ++k) EXPECT_OK(sph_probe_create(w.world, &gauge, &ids[k]));
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "4194304", sph_probe_create(w.world, &gauge, &extra));
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "points", sph_probe_create(w.world, &point, &extra));
  assert_true(extra.bits == 0x1234);
  EXPECT_OK(sph_world_save(w.world, NULL, 0, &size));
  saved = malloc(size);
  assert_non_null(saved);
  EXPECT_OK(sph_world_save(w.world, saved, size, &size));
  EXPECT_OK(sph_world_load(w.context, saved, size, &loaded));
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "points", sph_probe_create(loaded, &point, &extra));
  EXPECT_OK(sph_world_destroy(loaded));
  free(saved);
  EXPECT_OK(sph_probe_destroy(w.world, ids[0]));
  EXPECT_OK(sph_probe_create(w.world, &point, &id)); /* 2^22 - 65536 + 1 */
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "points", sph_probe_create(w.world, &gauge, &extra));
  EXPECT_OK(sph_probe_destroy(w.world, id));
  EXPECT_OK(sph_probe_create(w.world, &gauge, &ids[0])); /* full again */
  EXPECT_OK(support_world_close(&w));
}

/* A gauge's direction is any finite non-zero vector, however short: (1e-30, 0, 0) reads as
 * (1, 0, 0) does (its float square underflowed to 0, and the gauge read up instead). */
static void test_gauge_tiny_direction(void** state) {
  const uint32_t layers[3] = {6, 6, 6};
  float* lattice = NULL;
  uint32_t n = 0;
  support_world w;
  sph_world_def def;
  sph_probe_def gauge;
  sph_probe_id unit, tiny, huge;
  sph_probe_reading a, b, c;
  (void)state;
  assert_int_equal(support_fcc_box(layers, kStep, NULL, &lattice, &n), SPH_OK);
  def = probe_world_def(n);
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(support_spawn(w.world, lattice, NULL, n));
  free(lattice);
  EXPECT_OK(sph_probe_def_init(&gauge));
  gauge.kind = SPH_PROBE_GAUGE;
  gauge.position.x = -0.05f, gauge.position.y = 0.03f, gauge.position.z = 0.03f;
  gauge.length = 0.2f;
  gauge.direction.x = 1.0f;
  EXPECT_OK(sph_probe_create(w.world, &gauge, &unit));
  gauge.direction.x = 1e-30f;
  EXPECT_OK(sph_probe_create(w.world, &gauge, &tiny));
  gauge.direction.x = 3e38f; /* (its square overflows float: also a direction) */
  EXPECT_OK(sph_probe_create(w.world, &gauge, &huge));
  EXPECT_OK(sph_world_step(w.world, 0.01f));
  a = reading_of(w.world, unit);
  b = reading_of(w.world, tiny);
  c = reading_of(w.world, huge);
  assert_true(a.water_height > 0.05f); /* the block's width along x, about 0.08 m */
  assert_true(b.water_height == a.water_height && b.density == a.density);
  assert_true(c.water_height == a.water_height && c.density == a.density);
  EXPECT_OK(support_world_close(&w));
}

int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_input),    cmocka_unit_test(test_sampling),
      cmocka_unit_test(test_point_budget), cmocka_unit_test(test_gauge_tiny_direction),
      cmocka_unit_test(test_brute_force),  cmocka_unit_test(test_uniform_flow),
      cmocka_unit_test(test_resting_tank), cmocka_unit_test(test_resting_tank_walls_in_density),
  };
  /* With names, only those cases (e.g. test_resting_tank_walls_in_density to measure); without, all. */
  return capi_run_named_cases("physics_probes", tests, sizeof tests / sizeof tests[0], argc, argv);
}
