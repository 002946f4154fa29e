// SPDX-License-Identifier: MIT
/* Loads on colliders and probes on a DFSPH world (issues 16 item 3 and 17; src/physics/collider_loads.h,
 * src/cpu/cpu_dfsph_solver.cpp), against what they must equal. Lattice step 1 cm (spacing 1.41 cm,
 * h = 2.5 cm), DFSPH's default parameters (Jacobi solves).
 *   - momentum balance: a column collapsing in a closed tank; over the run the fluid's momentum
 *     change plus the impulses the colliders received (the walls' reactions of both solves, the
 *     solves' contact clamp, the collision response) equals gravity's impulse: within 1 % (the
 *     issue's), with and without the walls in the density. Measured 2e-7 of gravity's impulse;
 *     with the clamp's impulses left out of the loads (a diagnostic build) it missed by 99 % and
 *     11 %: the clamp carries nearly all of the walls' force without the walls in the density;
 *   - a fixed box submerged in a tank: its force against rho0 g V upwards once settled (printed;
 *     bound and why at the test). That the loads are the walls' reaction of the solves' pressure
 *     is checked against the host's sum by `physics_loads_breakdown --solver dfsph --check-loads`
 *     (the ctest physics_loads_breakdown_dfsph: within 1e-3 N, measured 9e-6 N);
 *   - a resting tank with the walls in the density: probes on the centre line read DFSPH's
 *     pressure (both solves', SPH_ATTRIBUTE_PRESSURE's) against the weight of the water above them
 *     per unit area: within 3 % (measured -0.48 to -1.38 %; the 1 % with
 *     DFLOADS_STRICT=1), and the difference of the probes at 4 and 16 cm within 3 % of the weight
 *     between them (measured -1.59 %; 1 % strict);
 *   - a checkpoint of a DFSPH world carries its probes: a loaded world reads the same probe and
 *     loads after the same step, bit for bit;
 *   - refusals: the conjugate gradients' density solve with the loads is UNSUPPORTED when set,
 *     the world unchanged.
 * DFLOADS_MEASURE=1 prints the measurements without asserting the bounds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_scenes.h"

static const double kStep = 0.01; /* support_fcc_box's step; the world's spacing is step sqrt 2 */
static const double kGravity = 9.81;

static int measuring(void) { return getenv("DFLOADS_MEASURE") != NULL; }
/* The 2 % (DFLOADS_STRICT=1) or the solver's accuracy now (see the test). */
static double buoyancy_bound(double now) { return getenv("DFLOADS_STRICT") ? 0.02 : now; }

static sph_world_def dfsph_def(uint32_t features, uint32_t capacity) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = (float)(kStep * sqrt(2.0));
  def.capacity = capacity;
  def.features = features;
  def.solver = SPH_SOLVER_DFSPH;
  return def;
}

/* DFLOADS_FLAGS=BITS (measuring): sph_dfsph_params.flags for the submerged box and the resting tank,
 * e.g. SPH_DFSPH_CORRECTED_GRADIENT (docs/validation.md, "Session 26"). */
static void apply_measured_flags(sph_world* world) {
  if (getenv("DFLOADS_FLAGS"))
    capi_set_dfsph_flags(world, (uint32_t)strtoul(getenv("DFLOADS_FLAGS"), NULL, 0));
}

/* ---- momentum balance ------------------------------------------------------------------------ */

/* A column 6 x 14 x 8 layers collapsing in a tank 16 x 30 x 8 layers for 0.3 s (the fluid hits the
 * far wall; test_collider_loads.c's case on DFSPH, capi_collapse_momentum_balance). Bound 1 % (the
 * issue's): the pair terms of the solves' velocity updates and of the non-pressure forces cancel
 * in pairs, so what is left is the rounding of float sums over ~1000 particles and ~100 substeps. */
static capi_momentum_balance momentum_balance_with(uint32_t features, uint32_t dfsph_flags,
                                                   uint32_t linear_solver) {
  const sph_world_def def = dfsph_def(SPH_FEATURE_COLLIDER_LOADS | features, 0);
  const capi_momentum_balance b = capi_collapse_momentum_balance(&def, dfsph_flags, linear_solver);
  print_message(
      "DFSPH momentum balance (features 0x%x, flags 0x%x, %u particles): fluid dP = (%.4g, %.4g, %.4g), "
      "colliders' J = (%.4g, %.4g, %.4g), gravity %.4g N s over %.3f s: residual %.3g %%\n",
      features, dfsph_flags, b.count, b.fluid_change[0], b.fluid_change[1], b.fluid_change[2], b.impulse[0],
      b.impulse[1], b.impulse[2], b.weight_impulse, b.time, 100.0 * b.error);
  assert_true(fabs(b.time - 0.3) < 1e-6);
  return b;
}

static void momentum_balance(uint32_t features) {
  assert_true(momentum_balance_with(features, 0u, 0u).error <= 0.01 || measuring());
}

static void test_momentum_balance_contacts(void** state) {
  (void)state;
  momentum_balance(SPH_FEATURE_NONE);
}

static void test_momentum_balance_boundary_density(void** state) {
  (void)state;
  momentum_balance(SPH_FEATURE_BOUNDARY_DENSITY);
}

/* The same with the corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT), whose pair terms are not
 * antisymmetric: the fluid's own pairs change its momentum, which no collider receives, so the
 * balance misses by the correction's error (docs/physics.md, DFSPH, the corrected gradient's
 * limits). Measured (CPU, session 26) 5.74 % of gravity's impulse (5.55 % before the walls' share
 * kept the correction's share: that change is not what misses). Bound 12 %, about twice that: a guard
 * on the documented limit, not the 1 % (asserted with DFLOADS_STRICT=1, a known issue). */
static void test_momentum_balance_corrected_gradient(void** state) {
  const capi_momentum_balance b =
      momentum_balance_with(SPH_FEATURE_BOUNDARY_DENSITY, SPH_DFSPH_CORRECTED_GRADIENT, 0u);
  (void)state;
  assert_true(b.error <= (getenv("DFLOADS_STRICT") ? 0.01 : 0.12) || measuring());
}

/* The same with the Chebyshev density solve (SPH_DFSPH_CHEBYSHEV):
 * its steps, negative ones included, go through the same velocity update, so the walls' reaction of
 * the solve's total pressure is the sum of its steps' and the balance holds as the plain solve's
 * (bound 1 %, the issue's). */
static void test_momentum_balance_chebyshev(void** state) {
  (void)state;
  assert_true(momentum_balance_with(SPH_FEATURE_BOUNDARY_DENSITY, 0u, SPH_DFSPH_CHEBYSHEV).error <= 0.01 ||
              measuring());
}

/* ---- buoyancy of a fixed submerged box ---------------------------------------------------------- */

/* test_collider_loads.c's submerged box (a 6 cm cube, centre 8 cm above the floor of a tank 16 x 16
 * cm filled to 20 cm) on DFSPH with the walls in the density: settled for 0.8 s, the box's force
 * averaged over the next 0.2 s against rho0 g V upwards. */
static void test_submerged_box_buoyancy(void** state) {
  const sph_world_def def = dfsph_def(SPH_FEATURE_COLLIDER_LOADS | SPH_FEATURE_BOUNDARY_DENSITY, 0);
  const double half = CAPI_SUBMERGED_HALF;
  capi_submerged_box s;
  double force[3], expected;
  (void)state;
  capi_submerged_box_open(&s, &def, NULL);
  apply_measured_flags(s.w.world);
  capi_mean_force(s.w.world, s.box, 50, 40, force);
  expected = s.w.def.rest_density * kGravity * 8.0 * half * half * half;
  print_message("DFSPH submerged box: force (%.4f, %.4f, %.4f) N, rho0 g V = %.4f N: buoyancy %+.2f %%\n",
                force[0], force[1], force[2], expected, 100.0 * (force[1] / expected - 1.0));
  /* Measured -3.80 % on the CPU (session 17, the scene's first layer kept below three faces; +1.01 %
   * without it, -4.23 % on the H200), -18.7 % before a solid's map corrected the distance (session
   * 16; docs/validation.md, "The submerged box per region" and "Session 17: the inverse's margin").
   * One draw of a window in which the water still sloshes (a sideways force of 0.6 N, 28 % of
   * rho0 g V): the bound, 8 %, is twice the largest reading since session 16 (it was 22 % for the
   * -12.9 % to -18.3 % spread before); the 2 % is asserted with DFLOADS_STRICT=1
   * (physics_dfsph_loads_strict_KNOWN_ISSUE). The force must still point up. Session 39's ensemble of
   * the breakdown program's box on CUDA (12 seeds): -1.3 to +4.7 % after 0.8 s, -5.8 to +4.9 % after
   * 2.4 s (docs/validation.md, "Session 39: the submerged box as an ensemble"). */
  assert_true((force[1] > 0.0 && fabs(force[1] / expected - 1.0) <= buoyancy_bound(0.08)) || measuring());
  capi_submerged_box_close(&s);
}

/* ---- probes in a resting tank ------------------------------------------------------------------ */

static sph_probe_id add_probe(sph_world* world, double x, double y, double z, uint32_t kind, double length) {
  sph_probe_def def;
  sph_probe_id id = {0};
  EXPECT_OK(sph_probe_def_init(&def));
  def.kind = (sph_probe_kind)kind;
  def.position.x = (float)x, def.position.y = (float)y, def.position.z = (float)z;
  def.length = (float)length;
  def.sampling = SPH_PROBE_EVERY_SUBSTEP;
  EXPECT_OK(sph_probe_create(world, &def, &id));
  return id;
}

static sph_probe_reading reading_of(const sph_world* world, sph_probe_id id) {
  sph_probe_reading r;
  EXPECT_OK(sph_probe_reading_init(&r));
  EXPECT_OK(sph_probe_get_reading(world, id, &r));
  return r;
}

/* test_probes.c's resting tank on DFSPH with the walls in the density: water 12 x 24 x 12 layers
 * settled in a closed tank for 0.8 s, then read over 0.4 s: a gauge through the centre, point
 * probes on the centre line at y = 4, 8, 12 and 16 cm, and the water's weight above each probe
 * (capi_count_above over each frame's positions, over the water's area capi_resting_water_area):
 * in a resting tank with vertical frictionless walls the pressure at a height is exactly the weight
 * above per unit area, whatever the compression, so the reference needs neither the gauge's level
 * nor where the floor is. Measuring (DFLOADS_MEASURE=1) also prints the reference before it, rho0 g d
 * below the gauge's surface raised by the floor's film (DFSPH holds the density at rho0, its bound
 * 0.1 %), and the centre's own column above each probe (a gauge from the probe up);
 * DFLOADS_WINDOW=N averages N frames instead of 20, DFLOADS_SCAN=1 adds point probes every quarter
 * step from 1 to 23 cm on the centre line against the weight above. */
#define DF_SCAN 89
static void resting_tank_probes(uint32_t dfsph_flags) {
  const sph_world_def def = dfsph_def(SPH_FEATURE_BOUNDARY_DENSITY, 0);
  const double* heights = capi_resting_heights;
  const double film = CAPI_RESTING_FILM, area = capi_resting_water_area();
  const int window = getenv("DFLOADS_WINDOW") ? atoi(getenv("DFLOADS_WINDOW")) : 20;
  const int scanning = getenv("DFLOADS_SCAN") != NULL;
  capi_resting_tank t;
  sph_world* world;
  sph_probe_id columns[4], scan[DF_SCAN];
  double pressure[4] = {0.0, 0.0, 0.0, 0.0}, density = 0.0, height = 0.0, time = 0.0, rho0, weight;
  double above[4] = {0.0, 0.0, 0.0, 0.0}, column_height[4] = {0.0, 0.0, 0.0, 0.0}, want[4], column_time = 0.0;
  double scan_y[DF_SCAN], scan_p[DF_SCAN], scan_above[DF_SCAN], scan_time = 0.0;
  int frames = 0;
  capi_resting_tank_open(&t, &def, NULL, SPH_PROBE_EVERY_SUBSTEP);
  world = t.w.world;
  if (dfsph_flags)
    capi_set_dfsph_flags(world, dfsph_flags);
  else
    apply_measured_flags(world);
  rho0 = t.w.def.rest_density;
  for (int k = 0; measuring() && k < 4; ++k)
    columns[k] = add_probe(world, CAPI_RESTING_WIDTH / 2, heights[k], CAPI_RESTING_WIDTH / 2, SPH_PROBE_GAUGE,
                           0.45 - heights[k]);
  for (int i = 0; i < DF_SCAN; ++i) {
    scan_y[i] = 0.01 + 0.0025 * i;
    scan_p[i] = scan_above[i] = 0.0;
    if (scanning)
      scan[i] =
          add_probe(world, CAPI_RESTING_WIDTH / 2, scan_y[i], CAPI_RESTING_WIDTH / 2, SPH_PROBE_POINT, 0.0);
  }
  for (int frame = 0; frame < 40 + window; ++frame) {
    EXPECT_OK(sph_world_step(world, 0.02f));
    if (frame < 40) continue;
    {
      const sph_probe_reading g = reading_of(world, t.gauge);
      height += g.water_height * g.time;
      time += g.time;
      for (int k = 0; k < 4; ++k) {
        const sph_probe_reading r = reading_of(world, t.probes[k]);
        assert_true(r.samples >= 1);
        assert_true(fabs(r.time - g.time) < 1e-9);
        pressure[k] += r.pressure * r.time;
        density += r.density * r.time / 4.0;
      }
      capi_count_above(world, t.w.def.kernel_radius, heights, 4, above, NULL);
      ++frames;
    }
    for (int k = 0; measuring() && k < 4; ++k) {
      const sph_probe_reading c = reading_of(world, columns[k]);
      column_height[k] += c.water_height * c.time;
      if (k == 0) column_time += c.time;
    }
    if (scanning) {
      for (int i = 0; i < DF_SCAN; ++i) {
        const sph_probe_reading r = reading_of(world, scan[i]);
        scan_p[i] += r.pressure * r.time;
        if (i == 0) scan_time += r.time;
      }
      capi_count_above(world, t.w.def.kernel_radius, scan_y, DF_SCAN, scan_above, NULL);
    }
  }
  height /= time;
  density /= time;
  weight = kGravity * t.w.mass / area / frames; /* Pa per particle above, per frame */
  print_message("DFSPH resting tank: gauge height %.5f m, the probes' mean density %.2f kg/m^3 (%+.3f %%)\n",
                height, density, 100.0 * (density / rho0 - 1.0));
  for (int k = 0; k < 4; ++k) {
    const double p = pressure[k] / time, d = film + height - heights[k], old = rho0 * kGravity * d;
    want[k] = weight * above[k];
    print_message("  probe at y = %.2f m: p = %.2f Pa, the weight above %.2f Pa (%+.2f %%)\n", heights[k], p,
                  want[k], 100.0 * (p / want[k] - 1.0));
    if (measuring())
      print_message(
          "    the centre's column above (a gauge from the probe up): %.2f Pa (%+.2f %%); the old reference, "
          "rho0 g d below the gauge's surface (d = %.4f m): %.2f Pa (%+.2f %%)\n",
          rho0 * kGravity * column_height[k] / column_time,
          100.0 * (p / (rho0 * kGravity * column_height[k] / column_time) - 1.0), d, old,
          100.0 * (p / old - 1.0));
    /* At depths of 8-20 cm (below the surface's kernel layer). DFSPH's hydrostatic pressure holds a
     * steady pattern of about +-1-2 % from slice to slice (docs/validation.md, "DFSPH: hydrostatic
     * tank"; validation_hydrostatic_dfsph_KNOWN_ISSUE), which a change at the walls moves: the
     * solver's pressure, not the probe's, is what is off (physics_probes checks the probe on DFSPH
     * against a brute-force sum). Bound: 3 %, kept from the reference before (not widened). Against
     * the weight above the CI's draw reads -0.48 to -1.38 % on the CPU; 9 draws (tank voxels 0.25-0.6
     * steps, lattice nudges of 1e-7 to 3e-7 m) -0.08 to -3.20 %, mean -1.66 %, one reading beyond
     * 3 % (voxel 0.25, 8 cm) (docs/validation.md, "The resting tank's probes against the weight
     * above"); the 1 % with DFLOADS_STRICT=1 (physics_dfsph_loads_strict_KNOWN_ISSUE). */
    assert_true(fabs(p / want[k] - 1.0) <= (getenv("DFLOADS_STRICT") ? 0.01 : 0.03) || measuring());
  }
  {
    /* The pressure difference between the probes at 4 and 16 cm against the weight of the water
     * between them per unit area (rho0 g 12 cm at rho0). Measured -1.59 % (the CI's draw, CPU); the
     * 9 draws above -0.68 to -3.15 %, one beyond 3 % (voxel 0.4). Bound 3 %, kept; the 1 %
     * with DFLOADS_STRICT=1. */
    const double difference = (pressure[0] - pressure[3]) / time, between = want[0] - want[3];
    print_message(
        "  p(4 cm) - p(16 cm) = %.2f Pa against the weight between them %.2f Pa (%+.2f %%; against rho0 g "
        "12 cm %+.2f %%)\n",
        difference, between, 100.0 * (difference / between - 1.0),
        100.0 * (difference / (rho0 * kGravity * (heights[3] - heights[0])) - 1.0));
    assert_true(fabs(difference / between - 1.0) <= (getenv("DFLOADS_STRICT") ? 0.01 : 0.03) || measuring());
  }
  for (int i = 0; scanning && i < DF_SCAN; ++i) {
    const double p = scan_p[i] / scan_time, w = weight * scan_above[i];
    const double old = rho0 * kGravity * (film + height - scan_y[i]);
    print_message("dfscan y %.4f p %.3f weight above %.3f (%+.3f %%) old %.3f (%+.3f %%)\n", scan_y[i], p, w,
                  100.0 * (p / w - 1.0), old, 100.0 * (p / old - 1.0));
  }
  capi_resting_tank_close(&t);
}

/* ---- checkpoints ------------------------------------------------------------------------------- */

/* A DFSPH world's checkpoint carries its probes (it was refused as corrupt while DFSPH had none):
 * a world loaded from it reads, after the same step, the same probe reading and loads bit for bit
 * (the same state, the same step). */
static void test_checkpoint_carries_probes(void** state) {
  const support_water_tank water = {{5, 6, 5}, kStep, {0.0, 0.0, 0.0}, {0.1, 0.2, 0.1}, 0.0f};
  const sph_world_def def = dfsph_def(SPH_FEATURE_COLLIDER_LOADS | SPH_FEATURE_BOUNDARY_DENSITY, 0);
  support_world w;
  sph_sdf* sdf = NULL;
  sph_collider_id tank;
  sph_probe_id probe;
  sph_world* loaded;
  sph_probe_reading a, b;
  sph_collider_loads la, lb;
  (void)state;
  EXPECT_OK(support_water_tank_open(&w, sph_test_backend(), &def, NULL, &water, &sdf, &tank, NULL));
  probe = add_probe(w.world, 0.05, 0.02, 0.05, SPH_PROBE_POINT, 0.0);
  EXPECT_OK(sph_world_step(w.world, 0.02f));
  loaded = capi_world_copy(w.context, w.world);
  EXPECT_OK(sph_world_step(w.world, 0.02f));
  EXPECT_OK(sph_world_step(loaded, 0.02f));
  a = reading_of(w.world, probe);
  b = reading_of(loaded, probe);
  la = capi_loads_of(w.world, tank);
  lb = capi_loads_of(loaded, tank);
  assert_true(a.samples > 0 && a.pressure > 0.0f);
  assert_true(a.samples == b.samples && a.density == b.density && a.pressure == b.pressure &&
              a.velocity.y == b.velocity.y && a.time == b.time);
  assert_true(la.force.x == lb.force.x && la.force.y == lb.force.y && la.force.z == lb.force.z);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

/* ---- refusals ---------------------------------------------------------------------------------- */

static void test_conjugate_gradients_refused(void** state) {
  const support_water_tank water = {{4, 4, 4}, kStep, {0.0, 0.0, 0.0}, {0.1, 0.1, 0.1}, 0.0f};
  const sph_world_def def = dfsph_def(SPH_FEATURE_COLLIDER_LOADS, 0);
  float *before = NULL, *after = NULL;
  uint32_t count = 0;
  support_world w;
  sph_sdf* sdf = NULL;
  sph_dfsph_params params;
  (void)state;
  EXPECT_OK(support_water_tank_open(&w, sph_test_backend(), &def, NULL, &water, &sdf, NULL, NULL));
  EXPECT_OK(sph_world_step(w.world, 0.01f)); /* Jacobi: the loads are read */
  EXPECT_OK(sph_dfsph_params_init(&params));
  EXPECT_OK(sph_world_get_dfsph_params(w.world, &params));
  params.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&before, &count));
  /* Refused when set, naming the feature, the world unchanged (it steps on with Jacobi). */
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "SPH_DFSPH_JACOBI", sph_world_set_dfsph_params(w.world, &params));
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "SPH_FEATURE_COLLIDER_LOADS",
               sph_world_set_dfsph_params(w.world, &params));
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&after, &count));
  assert_memory_equal(before, after, 3 * sizeof(float) * count);
  EXPECT_OK(sph_world_get_dfsph_params(w.world, &params));
  assert_int_equal(params.linear_solver, SPH_DFSPH_JACOBI);
  EXPECT_OK(sph_world_step(w.world, 0.01f));
  free(before);
  free(after);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

static void test_resting_tank_probes(void** state) {
  (void)state;
  resting_tank_probes(0u);
}

/* The same tank with the corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT): the same bounds. Before
 * session 26 its first frame ran out of substeps (every density solve capped, speeds of 4e16 m/s;
 * physics_dfsph_extremes_corrected_wall); measured since: +0.71, +0.69, +1.08, +0.30 % at 4, 8, 12 and
 * 16 cm against the default's -1.38, -0.48, -1.04, -1.13 %, the difference +1.04 % (-1.59 %). */
static void test_resting_tank_probes_corrected(void** state) {
  (void)state;
  resting_tank_probes(SPH_DFSPH_CORRECTED_GRADIENT);
}

int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_conjugate_gradients_refused),
      cmocka_unit_test(test_checkpoint_carries_probes),
      cmocka_unit_test(test_momentum_balance_contacts),
      cmocka_unit_test(test_momentum_balance_boundary_density),
      cmocka_unit_test(test_momentum_balance_corrected_gradient),
      cmocka_unit_test(test_momentum_balance_chebyshev),
      cmocka_unit_test(test_resting_tank_probes),
      cmocka_unit_test(test_resting_tank_probes_corrected),
      cmocka_unit_test(test_submerged_box_buoyancy),
  };
  /* With names, only those cases (the ctests split off the settled tanks, which the sanitizer
   * stage leaves out); without, all. */
  return capi_run_named_cases("physics_dfsph_loads", tests, sizeof tests / sizeof tests[0], argc, argv);
}
