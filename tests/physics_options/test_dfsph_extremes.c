// SPDX-License-Identifier: MIT
/* DFSPH at the extremes and against moving walls (issue 16 item 4). In every case each frame's
 * density solves either converged within the user's bound (sph_stats.density_error_max <= the
 * bound) or stopped at their cap and said so: sph_stats.pressure_solves_capped substeps and as
 * many SPH_EVENT_PRESSURE_SOLVE_CAPPED counts (never silently); likewise the divergence solve.
 * Likewise the largest error of one particle (sph_stats.density_error_largest) within
 * sph_dfsph_params.density_error_max. Every position stays finite and inside the tank (but at
 * step_factor 10, below). The cases:
 *   - cfl: a dam-break column at the largest step_factor the API accepts (10: a particle may move
 *     ten kernel radii a step) and at 1 (one kernel radius, the neighbour search's reach);
 *   - fine: a collapsing column at 0.1 mm steps (grad W about 1e15 m^-4 there, m about 2e-9 kg:
 *     dfsph_passes.h folds the mass into the gradient so that the sums stay in float range);
 *   - sheet: a sheet two lattice layers thick thrown onto the floor (no particle has a full
 *     neighbourhood: the factor and the divergence solve's neighbour floor at work);
 *   - kinematic: a paddle driven at 5 m/s through water, with the walls in the density: no
 *     particle ends inside it;
 *   - deforming: a ball collider whose SDF grows under resting water (sph_sdf_update every frame),
 *     with the walls in the density: no particle ends inside the grown ball;
 *   - largest: the collapsing column at a loose mean bound (1 %), with and without the bound on the
 *     largest particle error: without it some particle ends a solve above 5 %, with it none does.
 * Each case prints its substeps, iterations and worst errors (docs/validation.md, "DFSPH"). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

typedef struct solve_record {
  uint64_t substeps, pressure_iterations;
  uint32_t pressure_capped, divergence_capped, iterations_max;
  double density_error_max, divergence_error_max, density_error_largest;
} solve_record;

/* One frame, then the check of its solves against `bound` (the density solve's) and `divergence`
 * (the divergence solve's rate, 1/s, with the world's share a step), and of the largest particle error
 * against the world's density_error_max (never below the mean's bound). */
static void step_and_check(sph_world* world, float frame, float bound, float divergence, solve_record* rec) {
  sph_dfsph_params p;
  float largest_bound;
  sph_stats s;
  sph_event events[8];
  uint32_t count = 0, pressure_events = 0, divergence_events = 0;
  sph_result r;
  EXPECT_OK(sph_dfsph_params_init(&p));
  EXPECT_OK(sph_world_get_dfsph_params(world, &p));
  largest_bound = p.density_error_max > p.density_error ? p.density_error_max : p.density_error;
  EXPECT_OK(sph_world_step(world, frame));
  EXPECT_OK(sph_stats_init(&s));
  EXPECT_OK(sph_world_get_stats(world, &s));
  r = sph_world_get_events(world, events, 8, &count);
  assert_true(r == SPH_OK);
  for (uint32_t e = 0; e < count; ++e) {
    if (events[e].type == SPH_EVENT_PRESSURE_SOLVE_CAPPED) pressure_events += events[e].count;
    if (events[e].type == SPH_EVENT_DIVERGENCE_SOLVE_CAPPED) divergence_events += events[e].count;
  }
  /* Converged within the bound, or capped and reported in both places. */
  assert_int_equal(pressure_events, s.pressure_solves_capped);
  assert_int_equal(divergence_events, s.divergence_solves_capped);
  if (s.pressure_solves_capped == 0) assert_true(s.density_error_max <= bound);
  if (s.pressure_solves_capped == 0) assert_true(s.density_error_largest <= largest_bound);
  assert_true(s.density_error_largest >= s.density_error_max); /* one particle's error >= the mean */
  /* The divergence solve stops at the looser of its rate and its share a step over the substep's
   * dt (physics/dfsph.h); over a frame, the share's bound is largest at its shortest substep.
   * Float division rounds monotonically, so share / dt_min is at least the library's bound of any
   * of the frame's substeps. */
  if (s.divergence_solves_capped == 0) {
    const float per_step = p.divergence_error_per_step / s.dt_min;
    assert_true(s.divergence_error_max <= (per_step > divergence ? per_step : divergence));
  }
  assert_true(s.substeps > 0);
  assert_true(s.pressure_iterations >= 2u * s.substeps); /* the solve's minimum ran */
  rec->substeps += s.substeps;
  rec->pressure_iterations += s.pressure_iterations;
  rec->pressure_capped += s.pressure_solves_capped;
  rec->divergence_capped += s.divergence_solves_capped;
  if (s.pressure_iterations_max > rec->iterations_max) rec->iterations_max = s.pressure_iterations_max;
  if (s.density_error_max > rec->density_error_max) rec->density_error_max = s.density_error_max;
  if (s.divergence_error_max > rec->divergence_error_max) rec->divergence_error_max = s.divergence_error_max;
  if (s.density_error_largest > rec->density_error_largest)
    rec->density_error_largest = s.density_error_largest;
}

static void print_record(const char* name, const solve_record* rec, uint32_t particles) {
  printf(
      "%s: %u particles, %llu substeps, %.1f density iterations a substep (max %u), worst density error "
      "%.4f %% (one particle %.3f %%), worst divergence error %.3g 1/s, capped: %u density, %u divergence "
      "solves\n",
      name, particles, (unsigned long long)rec->substeps,
      (double)rec->pressure_iterations / (double)(rec->substeps ? rec->substeps : 1), rec->iterations_max,
      100.0 * rec->density_error_max, 100.0 * rec->density_error_largest, rec->divergence_error_max,
      rec->pressure_capped, rec->divergence_capped);
}

/* Every particle finite; returns how many lie farther than `slack` outside the box [lo, hi]
 * (each printed). */
static uint32_t count_outside(const sph_world* world, const double lo[3], const double hi[3], double slack) {
  float* x = NULL;
  uint32_t n = 0, outside = 0;
  EXPECT_OK(support_copy(world, SPH_ATTRIBUTE_POSITION, (void**)&x, &n));
  for (uint32_t i = 0; i < n; ++i) {
    int out = 0;
    for (int k = 0; k < 3; ++k) {
      assert_true(isfinite(x[3 * i + k]));
      out |= x[3 * i + k] < lo[k] - slack || x[3 * i + k] > hi[k] + slack;
    }
    if (out)
      printf("  particle %u outside the tank: (%.4f, %.4f, %.4f)\n", i, x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    outside += (uint32_t)out;
  }
  free(x);
  return outside;
}

static void assert_inside(const sph_world* world, const double lo[3], const double hi[3], double slack) {
  assert_int_equal(count_outside(world, lo, hi, slack), 0);
}

/* A DFSPH world of `spacing` with gravity and `features`, its step dt = step_factor h / v_max
 * clamped to dt_max (and to the viscous limit of `viscosity`, 0.05 h^2 rho0 / mu). */
static void open_dfsph(support_world* w, double spacing, uint32_t capacity, uint32_t features,
                       float step_factor, float dt_max, float viscosity) {
  sph_world_def def;
  sph_world_params params;
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.particle_spacing = (float)spacing;
  def.solver = SPH_SOLVER_DFSPH;
  def.features = features;
  sph_world_params_init(&params);
  params.step_factor = step_factor;
  params.dt_max = dt_max;
  params.viscosity = viscosity;
  params.max_substeps = 100000;
  EXPECT_OK(support_world_open(w, sph_test_backend(), &def, &params));
}

/* A column of layers[0] x layers[1] x layers[2] FCC layers of `step` in the corner of a closed
 * tank four columns long, `frames` frames of `frame` seconds, its step limited by step_factor
 * and dt_max only (no viscosity, so no viscous limit, and no depth limit); `dfsph` (NULL: the defaults) its
 * solves' parameters, and `out` (optional) the record of its solves. */
static uint32_t run_column_with(const char* name, const uint32_t layers[3], double step, float step_factor,
                                float dt_max, float frame, int frames, const sph_dfsph_params* dfsph,
                                solve_record* out) {
  const double spacing = step * sqrt(2.0);
  const double lo[3] = {0.0, 0.0, 0.0};
  const double hi[3] = {4.0 * layers[0] * step, 2.0 * layers[1] * step, layers[2] * step};
  support_world w;
  sph_sdf* tank = NULL;
  float* points = NULL;
  uint32_t n = 0, outside;
  solve_record rec;
  memset(&rec, 0, sizeof rec);
  EXPECT_OK(support_fcc_box(layers, step, NULL, &points, &n));
  open_dfsph(&w, spacing, n, 0u, step_factor, dt_max, 0.0f);
  {
    /* The depth step limit off: these columns test the CFL step (and, fine, 0.1 mm steps at dt_max),
     * which the limit (0.3 h / sqrt(g H): 6 ms for the 16-layer column, 0.5 ms for the fine one)
     * would otherwise cap from the first substep. */
    sph_dfsph_params p;
    EXPECT_OK(sph_dfsph_params_init(&p));
    if (dfsph) p = *dfsph;
    p.flags |= SPH_DFSPH_NO_DEPTH_STEP_LIMIT;
    EXPECT_OK(sph_world_set_dfsph_params(w.world, &p));
  }
  EXPECT_OK(support_tank_between(w.context, w.world, lo, hi, 0.5 * step, 0.0f, &tank, NULL));
  EXPECT_OK(support_spawn(w.world, points, NULL, n));
  free(points);
  for (int f = 0; f < frames; ++f)
    step_and_check(w.world, frame, dfsph ? dfsph->density_error : 0.001f, 1.0f, &rec);
  print_record(name, &rec, n);
  if (out) *out = rec;
  outside = count_outside(w.world, lo, hi, 0.5 * step);
  EXPECT_OK(sph_sdf_destroy(tank));
  EXPECT_OK(support_world_close(&w));
  return outside;
}

static uint32_t run_column(const char* name, const uint32_t layers[3], double step, float step_factor,
                           float dt_max, float frame, int frames) {
  return run_column_with(name, layers, step, step_factor, dt_max, frame, frames, NULL, NULL);
}

/* The collapsing column of the cfl case at step_factor 1 and a loose mean bound, 1 %, where the
 * density solve stops at its minimum of two iterations most substeps. Bounded by the mean alone
 * (density_error_max 1: 100 %), some particle ends a solve more than 5 % compressed (asserted, so
 * that the case tests something); with the default bound on the largest error (5 %) none does
 * unless its solve capped (step_and_check), at the price of more iterations. In a large world this
 * is what keeps a splash from throwing the water (docs/physics.md, DFSPH limits). */
static void test_largest_error_bound(void** state) {
  const uint32_t layers[3] = {8, 16, 4};
  sph_dfsph_params p;
  solve_record mean_only, bounded;
  (void)state;
  EXPECT_OK(sph_dfsph_params_init(&p));
  p.density_error = 0.01f;
  p.density_error_max = 1.0f;
  assert_int_equal(
      run_column_with("column, mean bound only", layers, 0.01, 1.0f, 0.05f, 0.05f, 8, &p, &mean_only), 0);
  assert_true(mean_only.density_error_largest > 0.05);
  p.density_error_max = 0.05f;
  assert_int_equal(
      run_column_with("column, largest error bound 5 %", layers, 0.01, 1.0f, 0.05f, 0.05f, 8, &p, &bounded),
      0);
  if (bounded.pressure_capped == 0) assert_true(bounded.density_error_largest <= 0.05);
  assert_true((double)bounded.pressure_iterations / (double)bounded.substeps >
              (double)mean_only.pressure_iterations / (double)mean_only.substeps);
}

/* The column collapses for 0.4 s (8 x 16 x 4 layers of 1 cm, 256 particles) in frames of 50 ms
 * with dt_max 50 ms, so that the CFL step binds: at step_factor 1 (a particle moves at most one
 * kernel radius a step, the neighbour search's reach) and at 10, the API's largest (ten kernel
 * radii a step, past neighbours it should have met): the solves may then cap; they must say so. */
static void test_step_at_the_cfl_limit(void** state) {
  const uint32_t layers[3] = {8, 16, 4};
  (void)state;
  assert_int_equal(run_column("column, step_factor 1", layers, 0.01, 1.0f, 0.05f, 0.05f, 8), 0);
  /* At 10 the solves hold (above), but the collision response does not keep every particle in
   * the 4 cm slab: measured, 3 of 256 particles end 1.2-1.8 cm beyond the side wall z = 4 cm,
   * near the floor (each moved several centimetres in one 50 ms step; the response projects once
   * along the SDF's gradient, which near the box's edge and beyond the grid's padding is not the
   * way back). Counted and printed, not asserted: ten kernel radii a step is past what the
   * response is for (docs/validation.md, "DFSPH at the extremes"). */
  (void)run_column("column, step_factor 10", layers, 0.01, 10.0f, 0.05f, 0.05f, 8);
}

/* The same kind of column at 0.1 mm steps (0.14 mm spacing), 6 x 12 x 4 layers, for 10 ms. */
static void test_fine_spacing(void** state) {
  const uint32_t layers[3] = {6, 12, 4};
  (void)state;
  assert_int_equal(run_column("column at 0.1 mm steps", layers, 1e-4, 0.4f, 1e-3f, 1e-3f, 10), 0);
}

/* A sheet two lattice layers thick (24 x 2 x 24 layers of 1 cm, 576 particles: no particle has
 * a full neighbourhood) thrown down at 3 m/s from 5 cm onto the floor of a tank, for 0.3 s: the
 * impact compresses it at once, then it spreads into a film. */
static void test_thin_sheet(void** state) {
  const uint32_t layers[3] = {24, 2, 24};
  const double step = 0.01, origin[3] = {0.0, 0.05, 0.0};
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {24 * step, 0.2, 24 * step};
  support_world w;
  sph_sdf* tank = NULL;
  float *points = NULL, *v = NULL;
  uint32_t n = 0;
  solve_record rec;
  (void)state;
  memset(&rec, 0, sizeof rec);
  EXPECT_OK(support_fcc_box(layers, step, origin, &points, &n));
  v = (float*)calloc(3 * (size_t)n, sizeof(float));
  assert_non_null(v);
  for (uint32_t i = 0; i < n; ++i) v[3 * i + 1] = -3.0f;
  open_dfsph(&w, step * sqrt(2.0), n, 0u, 0.4f, 1e-3f, 1.0f);
  EXPECT_OK(support_tank_between(w.context, w.world, lo, hi, 0.5 * step, 0.0f, &tank, NULL));
  EXPECT_OK(support_spawn(w.world, points, v, n));
  free(points), free(v);
  for (int f = 0; f < 15; ++f) step_and_check(w.world, 0.02f, 0.001f, 1.0f, &rec);
  print_record("sheet two layers thick thrown at 3 m/s", &rec, n);
  assert_inside(w.world, lo, hi, 0.5 * step);
  EXPECT_OK(sph_sdf_destroy(tank));
  EXPECT_OK(support_world_close(&w));
}

/* A paddle (a solid box 4 cm thick) driven at 5 m/s through water 10 cm deep in a channel, with
 * the walls in the density, for 0.06 s (30 cm, the water's length): after every frame no
 * particle lies inside the paddle deeper than a quarter spacing (the collision response's
 * safeguard, which the solves' wall pressure must not defeat by flinging particles through). */
static void test_fast_kinematic_paddle(void** state) {
  const float spacing = 0.02f, half_thickness = 0.02f, speed = 5.0f, frame = 0.005f;
  const double lo[3] = {-0.4, 0.0, -0.06}, hi[3] = {0.4, 0.4, 0.06};
  support_world w;
  sph_shape_desc d;
  sph_sdf *channel = NULL, *paddle = NULL;
  sph_collider_def cdef;
  sph_collider_id paddle_id, channel_id;
  sph_fill_box_desc fill;
  float paddle_x = -0.3f, *x = NULL, *v = NULL;
  uint32_t n = 0, m = 0;
  double mean_vx = 0.0, fastest = 0.0;
  solve_record rec;
  (void)state;
  memset(&rec, 0, sizeof rec);
  open_dfsph(&w, spacing, 8000, SPH_FEATURE_BOUNDARY_DENSITY, 0.4f, 1e-3f, 1.0f);
  EXPECT_OK(sph_shape_desc_init(&d));
  d.shape = SPH_SHAPE_BOX;
  d.half_extents.x = 0.4f, d.half_extents.y = 0.2f, d.half_extents.z = 0.06f;
  d.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(w.context, &d, &channel));
  EXPECT_OK(sph_collider_def_init(&cdef));
  cdef.sdf = channel;
  cdef.flags = SPH_COLLIDER_FLAG_INVERTED;
  cdef.transform = sph_transform_identity();
  cdef.transform.position.y = 0.2f;
  EXPECT_OK(sph_collider_create(w.world, &cdef, &channel_id));
  d.half_extents.x = half_thickness, d.half_extents.y = 0.3f, d.half_extents.z = 0.1f;
  EXPECT_OK(sph_sdf_create_shape(w.context, &d, &paddle));
  cdef.sdf = paddle;
  cdef.flags = 0;
  cdef.transform.position.x = paddle_x;
  EXPECT_OK(sph_collider_create(w.world, &cdef, &paddle_id));
  EXPECT_OK(sph_fill_box_desc_init(&fill));
  fill.min.x = -0.27f, fill.min.y = 0.0f, fill.min.z = -0.06f;
  fill.max.x = 0.1f, fill.max.y = 0.1f, fill.max.z = 0.06f;
  EXPECT_OK(sph_world_fill_box(w.world, &fill, &n));
  for (int f = 0; f < 12; ++f) {
    sph_transform target = sph_transform_identity();
    paddle_x += speed * frame;
    target.position.x = paddle_x, target.position.y = 0.2f;
    EXPECT_OK(sph_collider_set_target_transform(w.world, paddle_id, &target));
    step_and_check(w.world, frame, 0.001f, 1.0f, &rec);
    free(x);
    x = NULL;
    EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &m));
    assert_int_equal(m, n);
    for (uint32_t i = 0; i < m; ++i) {
      const int inside = fabsf(x[3 * i] - paddle_x) < half_thickness - 0.25f * spacing &&
                         fabsf(x[3 * i + 1] - 0.2f) < 0.3f && fabsf(x[3 * i + 2]) < 0.1f;
      assert_false(inside);
    }
  }
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &m));
  for (uint32_t i = 0; i < m; ++i) {
    mean_vx += v[3 * i];
    fastest = fmax(fastest, sqrt((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
                                 (double)v[3 * i + 2] * v[3 * i + 2]));
  }
  mean_vx /= m;
  print_record("paddle at 5 m/s", &rec, n);
  printf(
      "  water's mean x velocity %.3f m/s, fastest particle %.2f m/s after %.2f s, none inside the paddle\n",
      mean_vx, fastest, 12 * frame);
  assert_true(mean_vx > 0.25); /* the paddle pushed the water (a tenth of its speed, at least) */
  assert_inside(w.world, lo, hi, 0.5 * spacing);
  free(x), free(v);
  EXPECT_OK(sph_sdf_destroy(channel));
  EXPECT_OK(sph_sdf_destroy(paddle));
  EXPECT_OK(support_world_close(&w));
}

/* A ball SDF of n^3 voxels of 2 cm centred on the origin, radius `radius`. */
static void ball_grid(float* d, uint32_t n, float radius) {
  const float c = 0.5f * (float)(n - 1);
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        const float x = 0.02f * ((float)i - c), y = 0.02f * ((float)j - c), z = 0.02f * ((float)k - c);
        d[i + n * (j + n * k)] = sqrtf(x * x + y * y + z * z) - radius;
      }
}

/* Water (a 24 x 6 x 24 cm block, walls in the density) resting in a tank on a ball collider
 * whose SDF grows from 6 to 12 cm radius over 0.3 s (sph_sdf_update every 10 ms frame: a
 * deforming collider, its surface moving up at 0.2 m/s): the water is pushed up and aside, and
 * after every frame no particle lies inside the ball deeper than a quarter spacing. */
static void test_deforming_ball(void** state) {
  const float spacing = 0.02f;
  const uint32_t cells = 21, origin[3] = {0, 0, 0}, size[3] = {21, 21, 21};
  const double lo[3] = {-0.2, -0.2, -0.2}, hi[3] = {0.2, 0.3, 0.2};
  float* grid = (float*)malloc(sizeof(float) * cells * cells * cells);
  support_world w;
  sph_sdf_desc desc;
  sph_sdf *ball = NULL, *tank = NULL;
  sph_collider_def cdef;
  sph_collider_id id;
  sph_fill_box_desc fill;
  float radius = 0.06f, *x = NULL;
  uint32_t n = 0, m = 0;
  solve_record rec;
  (void)state;
  assert_non_null(grid);
  memset(&rec, 0, sizeof rec);
  open_dfsph(&w, spacing, 8000, SPH_FEATURE_BOUNDARY_DENSITY, 0.4f, 1e-3f, 1.0f);
  ball_grid(grid, cells, radius);
  EXPECT_OK(sph_sdf_desc_init(&desc));
  desc.distance.struct_size = sizeof desc.distance;
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = cells;
  desc.distance.index_to_local[0] = desc.distance.index_to_local[5] = desc.distance.index_to_local[10] =
      0.02f;
  desc.distance.index_to_local[3] = desc.distance.index_to_local[7] = desc.distance.index_to_local[11] =
      -0.01f * (float)(cells - 1);
  desc.distance.data = grid;
  EXPECT_OK(sph_sdf_create(w.context, &desc, &ball));
  EXPECT_OK(sph_collider_def_init(&cdef));
  cdef.sdf = ball;
  cdef.transform = sph_transform_identity();
  EXPECT_OK(sph_collider_create(w.world, &cdef, &id));
  EXPECT_OK(support_tank_between(w.context, w.world, lo, hi, 0.01, 0.0f, &tank, NULL));
  EXPECT_OK(sph_fill_box_desc_init(&fill));
  fill.min.x = -0.12f, fill.min.y = 0.065f, fill.min.z = -0.12f;
  fill.max.x = 0.12f, fill.max.y = 0.125f, fill.max.z = 0.12f;
  EXPECT_OK(sph_world_fill_box(w.world, &fill, &n));
  for (int f = 0; f < 30; ++f) {
    radius += 0.002f;
    ball_grid(grid, cells, radius);
    EXPECT_OK(sph_sdf_update(ball, SPH_SDF_CHANNEL_DISTANCE, origin, size, grid, SPH_MEMORY_HOST));
    step_and_check(w.world, 0.01f, 0.001f, 1.0f, &rec);
    free(x);
    x = NULL;
    EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &m));
    for (uint32_t i = 0; i < m; ++i) {
      const float r = sqrtf(x[3 * i] * x[3 * i] + x[3 * i + 1] * x[3 * i + 1] + x[3 * i + 2] * x[3 * i + 2]);
      assert_true(r > radius - 0.25f * spacing);
    }
  }
  print_record("ball growing at 0.2 m/s", &rec, n);
  assert_inside(w.world, lo, hi, 0.5 * spacing);
  free(x), free(grid);
  EXPECT_OK(sph_sdf_destroy(ball));
  EXPECT_OK(sph_sdf_destroy(tank));
  EXPECT_OK(support_world_close(&w));
}

/* The corrected gradient (SPH_DFSPH_CORRECTED_GRADIENT) with the walls in the density, started from a
 * lattice whose outer layers lie step / 2 from the walls (support_resting_tank's; the walls'
 * calibration rests them spacing / 2 away, so the first layers start compressed by about a quarter
 * of rho0 at the walls) for 0.2 s; the default gradient's run of the same start beside it. Before
 * the walls' share kept the correction's share of the zeroth-order term (dfsph_gradient_correction.h,
 * session 26) every density solve of the first frame capped and the step ran out of substeps with
 * speeds of 4e16 m/s. Now: every frame's solves within their bounds or capped and reported
 * (step_and_check), every particle finite and inside the tank, and the fastest particle no faster
 * than twice the default gradient's fastest over the same frames (measured 35 m/s against 44 m/s:
 * the compressed start throws droplets with either gradient). */
static float corrected_wall_start(uint32_t flags, solve_record* rec, uint32_t* particles) {
  const support_water_tank water = support_resting_tank();
  const double slack = 0.5 * water.step;
  support_world w;
  sph_world_def def;
  sph_world_params params;
  sph_dfsph_params dp;
  sph_sdf* sdf = NULL;
  float fastest = 0.0f;
  sph_world_def_init(&def);
  def.particle_spacing = (float)(water.step * sqrt(2.0));
  def.solver = SPH_SOLVER_DFSPH;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY;
  sph_world_params_init(&params);
  /* 36-53 substeps a frame are measured; a run that blows up fails its frame's step (SPH_INCOMPLETE)
   * within these 1,000 substeps instead of running 100,000. */
  params.max_substeps = 1000;
  EXPECT_OK(support_water_tank_open(&w, sph_test_backend(), &def, &params, &water, &sdf, NULL, particles));
  capi_set_dfsph_flags(w.world, flags);
  EXPECT_OK(sph_dfsph_params_init(&dp));
  EXPECT_OK(sph_world_get_dfsph_params(w.world, &dp));
  for (int f = 0; f < 10; ++f) {
    sph_stats s;
    step_and_check(w.world, 0.02f, dp.density_error, 1.0f, rec);
    EXPECT_OK(sph_stats_init(&s));
    EXPECT_OK(sph_world_get_stats(w.world, &s));
    if (s.max_speed > fastest) fastest = s.max_speed;
  }
  assert_inside(w.world, water.tank_min, water.tank_max, slack);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
  return fastest;
}

static void test_corrected_gradient_wall_start(void** state) {
  solve_record plain, corrected;
  uint32_t n = 0;
  float plain_fastest, corrected_fastest;
  (void)state;
  memset(&plain, 0, sizeof plain);
  memset(&corrected, 0, sizeof corrected);
  plain_fastest = corrected_wall_start(0u, &plain, &n);
  corrected_fastest = corrected_wall_start(SPH_DFSPH_CORRECTED_GRADIENT, &corrected, &n);
  print_record("resting tank started against its walls, default gradient", &plain, n);
  print_record("the same, corrected gradient", &corrected, n);
  printf("  fastest particle over 0.2 s: default %.3f m/s, corrected %.3f m/s\n", plain_fastest,
         corrected_fastest);
  assert_true(corrected_fastest <= 2.0f * plain_fastest);
}

/* argv[1] picks one case (cfl | fine | sheet | kinematic | deforming | largest | corrected_wall); none runs
 * them all. */
int main(int argc, char** argv) {
  const struct CMUnitTest all[] = {
      cmocka_unit_test(test_step_at_the_cfl_limit),
      cmocka_unit_test(test_fine_spacing),
      cmocka_unit_test(test_thin_sheet),
      cmocka_unit_test(test_fast_kinematic_paddle),
      cmocka_unit_test(test_deforming_ball),
      cmocka_unit_test(test_largest_error_bound),
      cmocka_unit_test(test_corrected_gradient_wall_start),
  };
  const char* names[] = {"cfl", "fine", "sheet", "kinematic", "deforming", "largest", "corrected_wall"};
  if (argc >= 2)
    for (int i = 0; i < 7; ++i)
      if (strcmp(argv[1], names[i]) == 0) return _cmocka_run_group_tests(names[i], &all[i], 1, NULL, NULL);
  return cmocka_run_group_tests(all, NULL, NULL);
}
