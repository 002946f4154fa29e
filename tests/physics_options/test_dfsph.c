// SPDX-License-Identifier: MIT
/* DFSPH (issue 16 item 4): the state a checkpoint carries and a failed step puts back.
 * - checkpoint: a ball falling into a closed tank (its solves warm-started from the last
 *   substep's pressures, which the checkpoint carries), saved mid-run: the loaded world and the
 *   original continue bit for bit, with and without the walls in the density; sph_world_restore
 *   of the checkpoint into the original gives the same state again;
 * - rollback: a gravity of 3e38 m/s^2 makes v* = v + dt g overflow in the first substep; the step
 *   fails with SPH_ERROR_NON_FINITE, the world is as before (particles and the solves' warm
 *   starts: the next steps equal those of a world that never failed);
 * - the conjugate gradients' density solve refused where it does not run (the walls in the
 *   density, on either backend) when the parameters are set, not at the step: both
 *   setters return SPH_ERROR_UNSUPPORTED naming the reason, the parameters stay Jacobi and the
 *   world steps;
 * - the depth step limit dt <= f h / sqrt(|g| H) (docs/physics.md, DFSPH, Limits): a column at rest
 *   under an oblique gravity takes f h / sqrt(|g| H), H brute-forced from the particles' positions
 *   (max - min of x . g / |g| in double); off by SPH_DFSPH_NO_DEPTH_STEP_LIMIT and without gravity
 *   it takes dt_max, and dt_min wins over it; a world loaded or restored from a checkpoint takes
 *   the same limited steps and trajectory bit for bit (H is measured, not stored); bad factors
 * (INVALID_ARGUMENT) and unknown flag bits (UNSUPPORTED) are refused with the world unchanged;
 * - the divergence bound as a share a step (divergence_error_per_step): over substeps of two
 *   lengths it is the rate share / dt of each substep, bit for bit; a looser share takes fewer
 *   iterations; its range is checked. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

static const float kSpacing = 0.02f;

static void open_dfsph_tank(scene* s, uint32_t features, float gravity_y) {
  sph_world_def def;
  sph_world_params params;
  support_tank tank;
  sph_fill_sphere_desc ball;
  uint32_t n = 0;
  sph_world_def_init(&def);
  def.capacity = 1000;
  def.particle_spacing = kSpacing;
  def.solver = SPH_SOLVER_DFSPH;
  def.features = features;
  sph_world_params_init(&params);
  params.gravity.y = gravity_y;
  SCENE_OK(support_world_open(s, sph_test_backend(), &def, &params));
  memset(&tank, 0, sizeof tank);
  tank.centre.y = 0.1f;
  tank.half_extents.x = tank.half_extents.y = tank.half_extents.z = 0.12f;
  tank.voxel_size = 0.01f;
  SCENE_OK(support_tank_create(s->context, s->world, &tank, NULL, NULL));
  sph_fill_sphere_desc_init(&ball);
  /* Above the floor (y = -0.02): the lowest lattice layer, 7.07 cm below the centre, 1 cm (half a
   * spacing) above it. (Centred on the origin, 114 of the 381 particles started inside the floor
   * and the push-out threw them at 28 m/s; now the ball lands at 1 m/s within the 6 frames before
   * the save, and the solves carry pressures there: 369 of 381 positive, up to 6 kPa.) */
  ball.center.y = 0.061f;
  ball.radius = 0.08f;
  ball.velocity.y = -1.0f;
  SCENE_OK(sph_world_fill_sphere(s->world, &ball, &n));
  assert_true(n > 200);
}

static void step_frames(scene* s, int frames) {
  for (int f = 0; f < frames; ++f) SCENE_OK(sph_world_step(s->world, 0.005f));
}

static void expect_same_state(scene* a, sph_world* b_world, uint32_t n) {
  scene b = *a;
  float* x = (float*)malloc(12 * (size_t)n);
  float* y = (float*)malloc(12 * (size_t)n);
  assert_true(x && y);
  b.world = b_world;
  assert_int_equal(scene_positions(a, x, n), n);
  assert_int_equal(scene_positions(&b, y, n), n);
  assert_memory_equal(x, y, 12 * (size_t)n);
  assert_int_equal(scene_velocities(a, x, n), n);
  assert_int_equal(scene_velocities(&b, y, n), n);
  assert_memory_equal(x, y, 12 * (size_t)n);
  free(x);
  free(y);
}

static void run_checkpoint(uint32_t features) {
  scene s;
  sph_world* loaded = NULL;
  uint64_t size = 0;
  uint32_t n = 0;
  void* buffer;
  sph_stats stats;
  open_dfsph_tank(&s, features, -9.81f);
  step_frames(&s, 6); /* the ball lands: the solves carry pressures */
  sph_stats_init(&stats);
  SCENE_OK(sph_world_get_stats(s.world, &stats));
  assert_true(stats.pressure_iterations > 0);
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  SCENE_OK(sph_world_save(s.world, NULL, 0, &size));
  buffer = malloc(size);
  assert_non_null(buffer);
  SCENE_OK(sph_world_save(s.world, buffer, size, &size));
  SCENE_OK(sph_world_load(s.context, buffer, size, &loaded));
  step_frames(&s, 4);
  {
    scene l = s;
    l.world = loaded;
    step_frames(&l, 4);
  }
  expect_same_state(&s, loaded, n);
  SCENE_OK(sph_world_restore(s.world, buffer, size));
  step_frames(&s, 4);
  expect_same_state(&s, loaded, n);
  SCENE_OK(sph_world_destroy(loaded));
  free(buffer);
  scene_close(&s);
}

static void test_checkpoint_bitwise(void** state) {
  (void)state;
  run_checkpoint(SPH_FEATURE_NONE);
}

static void test_checkpoint_bitwise_boundary_density(void** state) {
  (void)state;
  run_checkpoint(SPH_FEATURE_BOUNDARY_DENSITY);
}

static void test_non_finite_rolls_back(void** state) {
  scene s, twin;
  uint32_t n = 0;
  sph_world_params huge;
  (void)state;
  open_dfsph_tank(&s, SPH_FEATURE_NONE, -9.81f);
  open_dfsph_tank(&twin, SPH_FEATURE_NONE, -9.81f);
  step_frames(&s, 6);
  step_frames(&twin, 6);
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  huge = s.params;
  SCENE_OK(sph_world_get_params(s.world, &huge));
  huge.gravity.y = -3e38f;
  SCENE_OK(sph_world_set_params(s.world, &huge));
  assert_int_equal(sph_world_step(s.world, 0.005f), SPH_ERROR_NON_FINITE);
  huge.gravity.y = -9.81f;
  SCENE_OK(sph_world_set_params(s.world, &huge));
  expect_same_state(&s, twin.world, n);
  /* The warm starts were put back too: the next frames equal the twin's. */
  step_frames(&s, 3);
  step_frames(&twin, 3);
  expect_same_state(&s, twin.world, n);
  scene_close(&s);
  scene_close(&twin);
}

static void test_cg_refused_when_set(void** state) {
  scene s;
  sph_dfsph_params dp, now;
  (void)state;
  open_dfsph_tank(&s, SPH_FEATURE_BOUNDARY_DENSITY, -9.81f);
  sph_dfsph_params_init(&dp);
  dp.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
  dp.density_error = 0.002f; /* with the refused field: nothing of the struct is taken */
  assert_int_equal(sph_world_set_dfsph_params(s.world, &dp), SPH_ERROR_UNSUPPORTED);
  assert_non_null(strstr(sph_get_last_error(), "params->linear_solver"));
  assert_non_null(strstr(sph_get_last_error(), "SPH_FEATURE_BOUNDARY_DENSITY"));
  assert_int_equal(sph_world_set_physics_params(s.world, SPH_PARAMS_DFSPH, &dp), SPH_ERROR_UNSUPPORTED);
  sph_dfsph_params_init(&now);
  SCENE_OK(sph_world_get_dfsph_params(s.world, &now));
  assert_int_equal(now.linear_solver, SPH_DFSPH_JACOBI);
  assert_true(now.density_error == 0.001f);
  step_frames(&s, 1);
  scene_close(&s);
}

/* A DFSPH column 10 x 60 x 10 cm (spacing 2 cm, h 3.6 cm) at rest, no walls: only its first substep
 * is looked at, before any pressure moves it. */
static void open_column(scene* s, sph_vec3 gravity, float dt_max, uint32_t max_substeps,
                        uint32_t dfsph_flags) {
  sph_world_def def;
  sph_world_params params;
  sph_dfsph_params dp;
  sph_fill_box_desc box;
  uint32_t n = 0;
  sph_world_def_init(&def);
  def.capacity = 8000;
  def.particle_spacing = kSpacing;
  def.solver = SPH_SOLVER_DFSPH;
  sph_world_params_init(&params);
  params.gravity = gravity;
  params.dt_max = dt_max;
  params.dt_min = 1e-6f;
  params.max_substeps = max_substeps;
  SCENE_OK(support_world_open(s, sph_test_backend(), &def, &params));
  sph_dfsph_params_init(&dp);
  dp.flags = dfsph_flags;
  SCENE_OK(sph_world_set_dfsph_params(s->world, &dp));
  sph_fill_box_desc_init(&box);
  box.max.x = 0.1f;
  box.max.y = 0.6f;
  box.max.z = 0.1f;
  SCENE_OK(sph_world_fill_box(s->world, &box, &n));
  assert_true(n > 300);
}

/* H: max - min of x . g / |g| over the world's particles, in double. */
static double brute_force_height(scene* s, sph_vec3 g) {
  uint32_t n = 0;
  float* x;
  double lo = INFINITY, hi = -INFINITY;
  const double gm = sqrt((double)g.x * g.x + (double)g.y * g.y + (double)g.z * g.z);
  SCENE_OK(sph_world_get_particle_count(s->world, &n));
  x = (float*)malloc(12 * (size_t)n);
  assert_non_null(x);
  assert_int_equal(scene_positions(s, x, n), n);
  for (uint32_t i = 0; i < n; ++i) {
    const double y = ((double)x[3 * i] * g.x + (double)x[3 * i + 1] * g.y + (double)x[3 * i + 2] * g.z) / gm;
    lo = y < lo ? y : lo;
    hi = y > hi ? y : hi;
  }
  free(x);
  return hi - lo;
}

/* The first substep's dt of a frame of frame_dt (sph_stats.dt_max; one substep when max_substeps is 1). */
static float first_dt(scene* s, float frame_dt) {
  sph_stats st;
  const sph_result r = sph_world_step(s->world, frame_dt);
  assert_true(r == SPH_OK || r == SPH_INCOMPLETE);
  sph_stats_init(&st);
  SCENE_OK(sph_world_get_stats(s->world, &st));
  assert_true(st.substeps >= 1);
  return st.dt_max;
}

static void test_depth_step_limit(void** state) {
  scene s;
  sph_world_def def;
  sph_dfsph_params dp;
  const sph_vec3 g = {2.0f, -9.0f, 1.5f};
  double gm, height, want, frame, lo, hi, n;
  float dt;
  (void)state;
  open_column(&s, g, 1.0f, 1u, 0u); /* dt_max 1 s: the water at rest, the depth limit alone binds */
  sph_world_def_init(&def);
  SCENE_OK(sph_world_get_def(s.world, &def));
  sph_dfsph_params_init(&dp);
  SCENE_OK(sph_world_get_dfsph_params(s.world, &dp));
  assert_true(dp.depth_step_factor == 0.3f); /* the default */
  gm = sqrt((double)g.x * g.x + (double)g.y * g.y + (double)g.z * g.z);
  height = brute_force_height(&s, g);
  assert_true(height > 0.55 && height < 0.65);
  want = 0.3 * (double)def.kernel_radius / sqrt(gm * height);
  /* One substep of a frame a million of them long: landing_dt spreads the frame over
   * n = ceil(frame / dt_c - 1e-4) steps (step_control.h), so the step taken, frame / n, brackets
   * the controller's dt_c within one part in a million: frame / (n + 1e-4) <= dt_c <
   * frame / (n - 1 + 1e-4). The tolerance on top, 1e-6 of dt, is float rounding: the library
   * projects the positions and evaluates f h / sqrt(|g| H) in float (a few ulps, 6e-8 each). */
  frame = (double)(float)(1e6 * want);
  dt = first_dt(&s, (float)frame);
  n = floor(frame / (double)dt + 0.5);
  assert_true(n > 9.9e5 && n < 1.01e6);
  lo = frame / (n + 1e-4);
  hi = frame / (n - 1.0 + 1e-4);
  print_message("depth limit: H %.6f m, f h / sqrt(|g| H) %.9g s, the controller's in [%.9g, %.9g) s\n",
                height, want, lo, hi);
  assert_true(want >= lo * (1.0 - 1e-6) && want < hi * (1.0 + 1e-6));
  scene_close(&s);

  /* Off by the flag, and without gravity: dt_max (20 steps of 50 ms in a 1 s frame). */
  open_column(&s, g, 0.05f, 1u, SPH_DFSPH_NO_DEPTH_STEP_LIMIT);
  assert_true(first_dt(&s, 1.0f) == (float)(1.0 / 20.0));
  scene_close(&s);
  {
    const sph_vec3 none = {0.0f, 0.0f, 0.0f};
    open_column(&s, none, 0.05f, 1u, 0u);
    assert_true(first_dt(&s, 1.0f) == (float)(1.0 / 20.0));
    scene_close(&s);
  }
  /* dt_min wins over the limit (a fixed-step run pins dt_min = dt_max). */
  open_column(&s, g, 0.05f, 1u, 0u);
  {
    sph_world_params p;
    sph_world_params_init(&p);
    SCENE_OK(sph_world_get_params(s.world, &p));
    p.dt_min = 0.05f;
    SCENE_OK(sph_world_set_params(s.world, &p));
  }
  assert_true(first_dt(&s, 1.0f) == (float)(1.0 / 20.0));
  scene_close(&s);
}

/* H is measured, never stored: a world loaded from a checkpoint (and one restored from it) takes
 * the same limited steps and the same trajectory as the original, bit for bit. */
static void test_depth_step_after_checkpoint(void** state) {
  scene s, l;
  const sph_vec3 g = {0.0f, -9.81f, 0.0f};
  uint64_t size = 0;
  uint32_t n = 0;
  void* buffer;
  sph_stats a, b;
  (void)state;
  open_column(&s, g, 0.05f, 10000u, 0u);
  SCENE_OK(sph_world_step(s.world, 0.02f));
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  SCENE_OK(sph_world_save(s.world, NULL, 0, &size));
  buffer = malloc(size);
  assert_non_null(buffer);
  SCENE_OK(sph_world_save(s.world, buffer, size, &size));
  l = s;
  SCENE_OK(sph_world_load(s.context, buffer, size, &l.world));
  for (int f = 0; f < 2; ++f) {
    SCENE_OK(sph_world_step(s.world, 0.02f));
    SCENE_OK(sph_world_step(l.world, 0.02f));
    sph_stats_init(&a);
    sph_stats_init(&b);
    SCENE_OK(sph_world_get_stats(s.world, &a));
    SCENE_OK(sph_world_get_stats(l.world, &b));
    assert_int_equal(a.substeps, b.substeps);
    assert_true(a.dt_min == b.dt_min && a.dt_max == b.dt_max);
    assert_true(a.dt_max < 0.006f); /* the limit binds (about 4.6 ms; dt_max 50 ms) */
  }
  expect_same_state(&s, l.world, n);
  SCENE_OK(sph_world_restore(s.world, buffer, size));
  SCENE_OK(sph_world_step(s.world, 0.02f));
  SCENE_OK(sph_world_step(s.world, 0.02f));
  expect_same_state(&s, l.world, n);
  SCENE_OK(sph_world_destroy(l.world));
  free(buffer);
  scene_close(&s);
}

/* A float field of sph_dfsph_params at `offset` whose range is (0, 1] with 0 the default
 * `fallback`: `value` is accepted; -0.1, 1.5, NaN and the infinities are INVALID_ARGUMENT naming
 * the field, the world's parameters unchanged; 0 takes the default; 1, the largest, is accepted. */
static float* dfsph_field(sph_dfsph_params* p, size_t offset) { return (float*)((char*)p + offset); }

static void expect_unit_range_field(sph_world* world, size_t offset, const char* name, float value,
                                    float fallback) {
  sph_dfsph_params dp, now;
  const float bad[] = {-0.1f, 1.5f, NAN, INFINITY, -INFINITY};
  sph_dfsph_params_init(&dp);
  *dfsph_field(&dp, offset) = value;
  SCENE_OK(sph_world_set_dfsph_params(world, &dp));
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
    sph_dfsph_params_init(&dp);
    *dfsph_field(&dp, offset) = bad[k];
    assert_int_equal(sph_world_set_dfsph_params(world, &dp), SPH_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(sph_get_last_error(), name));
  }
  sph_dfsph_params_init(&now);
  SCENE_OK(sph_world_get_dfsph_params(world, &now));
  assert_true(*dfsph_field(&now, offset) == value); /* unchanged */
  sph_dfsph_params_init(&dp);
  *dfsph_field(&dp, offset) = 0.0f;
  SCENE_OK(sph_world_set_dfsph_params(world, &dp));
  SCENE_OK(sph_world_get_dfsph_params(world, &now));
  assert_true(*dfsph_field(&now, offset) == fallback);
  *dfsph_field(&dp, offset) = 1.0f;
  SCENE_OK(sph_world_set_dfsph_params(world, &dp));
}

static void test_depth_step_params_refused(void** state) {
  scene s;
  sph_dfsph_params dp, now;
  const sph_vec3 g = {0.0f, -9.81f, 0.0f};
  (void)state;
  open_column(&s, g, 0.05f, 1u, 0u);
  expect_unit_range_field(s.world, offsetof(sph_dfsph_params, depth_step_factor), "depth_step_factor", 0.2f,
                          0.3f);
  sph_dfsph_params_init(&dp);
  dp.depth_step_factor = 0.2f;
  SCENE_OK(sph_world_set_dfsph_params(s.world, &dp));
  dp.flags = 0x8u; /* an unknown bit: UNSUPPORTED, as every bit set's unknown bits (param_table.h) */
  assert_int_equal(sph_world_set_dfsph_params(s.world, &dp), SPH_ERROR_UNSUPPORTED);
  assert_non_null(strstr(sph_get_last_error(), "flags"));
  sph_dfsph_params_init(&now);
  SCENE_OK(sph_world_get_dfsph_params(s.world, &now));
  assert_true(now.depth_step_factor == 0.2f); /* unchanged */
  assert_int_equal(now.flags, 0u);
  scene_close(&s);
}

/* The divergence bound as a share of rho0 a step (sph_dfsph_params.divergence_error_per_step): the
 * falling ball of the checkpoint tests, its frames alternating between 1 ms and 0.25 ms (dt_max
 * 1 ms: one substep a frame, whose dt is the frame's length), `frames` frames. The world's divergence
 * solve is bounded by the share `share` alone (a rate of 1e-6 1/s, far stricter, so the looser share
 * governs) or, with `as_rate`, by the rate share / dt set before each frame alone (a share of 1e-9).
 * Checks each frame's solve against share / dt unless capped, and returns the divergence
 * iterations and the particles' positions and velocities (malloc'ed, 6 floats a particle). */
static const float kFrames[2] = {0.001f, 0.00025f};

static uint64_t run_alternating_steps(float share, int as_rate, int frames, float** state_out,
                                      uint32_t* n_out) {
  scene s;
  sph_world_params params;
  sph_dfsph_params dp;
  sph_stats st;
  uint64_t iterations = 0;
  uint32_t n = 0;
  open_dfsph_tank(&s, 0u, -9.81f);
  sph_world_params_init(&params);
  SCENE_OK(sph_world_get_params(s.world, &params));
  params.dt_max = kFrames[0];
  SCENE_OK(sph_world_set_params(s.world, &params));
  sph_dfsph_params_init(&dp);
  dp.divergence_error = 1e-6f;
  dp.divergence_error_per_step = as_rate ? 1e-9f : share;
  for (int f = 0; f < frames; ++f) {
    const float frame = kFrames[f % 2], bound = share / frame;
    if (as_rate || f == 0) {
      if (as_rate) dp.divergence_error = bound;
      SCENE_OK(sph_world_set_dfsph_params(s.world, &dp));
    }
    SCENE_OK(sph_world_step(s.world, frame));
    sph_stats_init(&st);
    SCENE_OK(sph_world_get_stats(s.world, &st));
    assert_int_equal(st.substeps, 1);
    assert_true(st.dt_min == frame);
    if (st.divergence_solves_capped == 0) assert_true(st.divergence_error_max <= bound);
    iterations += st.divergence_iterations;
  }
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  *state_out = (float*)malloc(24 * (size_t)n);
  assert_non_null(*state_out);
  assert_int_equal(scene_positions(&s, *state_out, n), n);
  assert_int_equal(scene_velocities(&s, *state_out + 3 * (size_t)n, n), n);
  *n_out = n;
  scene_close(&s);
  return iterations;
}

/* - A share S is the rate S / dt of each substep's own dt: the world bounded by the share alone
 *   steps bit for bit as the world whose rate is set to S / dt before each frame (IEEE division on
 *   both backends, physics/dfsph.h). The frames alternate between two lengths, so a bound taken
 *   from another substep's dt (the last one's, 4 times longer or shorter) would stop some solve at
 *   another iteration and move the particles;
 * - the share is used: a looser share (10x) takes fewer divergence iterations, and the strict one
 *   more than the solve's minimum (one a substep), so the bound is what stops it. */
static void test_divergence_bound_per_step(void** state) {
  const int frames = 80;        /* 50 ms: the ball lands after about 20 */
  const float share = 0.00002f; /* 0.02 / s at 1 ms, 0.08 / s at 0.25 ms */
  float *by_share = NULL, *by_rate = NULL, *loose = NULL;
  uint32_t n_share = 0, n_rate = 0, n_loose = 0;
  uint64_t it_share, it_rate, it_loose;
  (void)state;
  it_share = run_alternating_steps(share, 0, frames, &by_share, &n_share);
  it_rate = run_alternating_steps(share, 1, frames, &by_rate, &n_rate);
  it_loose = run_alternating_steps(10.0f * share, 0, frames, &loose, &n_loose);
  printf("divergence iterations over %d substeps: share %g %llu, its rate %llu, share %g %llu\n", frames,
         (double)share, (unsigned long long)it_share, (unsigned long long)it_rate, (double)(10.0f * share),
         (unsigned long long)it_loose);
  assert_int_equal(n_share, n_rate);
  assert_int_equal(it_share, it_rate);
  assert_memory_equal(by_share, by_rate, 24 * (size_t)n_share);
  assert_true(it_share > (uint64_t)frames);
  assert_true(it_loose < it_share);
  free(by_share);
  free(by_rate);
  free(loose);
}

/* The share's range: (0, 1], 0 the default (0.001); -0.1, 1.5, NaN and the infinities are
 * INVALID_ARGUMENT naming the field, the world's parameters unchanged. */
static void test_divergence_per_step_params(void** state) {
  scene s;
  sph_dfsph_params dp;
  (void)state;
  open_column(&s, (sph_vec3){0.0f, -9.81f, 0.0f}, 0.05f, 1u, 0u);
  sph_dfsph_params_init(&dp);
  assert_true(dp.divergence_error_per_step == 0.001f); /* the default */
  expect_unit_range_field(s.world, offsetof(sph_dfsph_params, divergence_error_per_step),
                          "divergence_error_per_step", 0.002f, 0.001f);
  SCENE_OK(sph_world_step(s.world, 0.01f));
  scene_close(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_checkpoint_bitwise),
      cmocka_unit_test(test_checkpoint_bitwise_boundary_density),
      cmocka_unit_test(test_non_finite_rolls_back),
      cmocka_unit_test(test_cg_refused_when_set),
      cmocka_unit_test(test_depth_step_limit),
      cmocka_unit_test(test_depth_step_after_checkpoint),
      cmocka_unit_test(test_depth_step_params_refused),
      cmocka_unit_test(test_divergence_bound_per_step),
      cmocka_unit_test(test_divergence_per_step_params),
  };
  return cmocka_run_group_tests_name("physics_dfsph", tests, NULL, NULL);
}
