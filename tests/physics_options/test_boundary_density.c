// SPDX-License-Identifier: MIT
/* Walls in the density (SPH_FEATURE_BOUNDARY_DENSITY; src/physics/boundary_density.h), against
 * what it is for: particles at a wall read rest density instead of the summation's deficit, and
 * the wall holds the fluid with the pressure it should. Spacing s = 2 cm, h = 1.8 s.
 *   - a resting FCC lattice against a flat wall along its (100), (110) and (111) planes, first
 *     layer s/2 from the wall: the first layer reads rho0 within the calibration's spread (the
 *     bounds below say why each), and 19-29 % low without the feature;
 *   - an FCC block from sph_world_fill_box closed in a box (an inverted collider): every
 *     particle, edges and corners included, within the bound;
 *   - a hydrostatic tank settles with its pressure near the walls closer to rho0 g d than
 *     without;
 *   - a kinematic box pushes fluid across a tank without a particle entering it;
 *   - an asset changed by sph_sdf_update gives the densities a freshly made asset of the same
 *     data gives (its map was recomputed), and different ones from before the change; also when
 *     the change comes in two halves of the grid, a step apart (the CPU recomputes each half's
 *     reach of the map only). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

static const float kSpacing = 0.02f;

static sph_world_def boundary_def(uint32_t features, uint32_t capacity) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = kSpacing;
  def.capacity = capacity;
  def.features = features;
  return def;
}

/* A quaternion turning unit vector a into unit vector b (not antiparallel). */
static sph_quat turn(const double a[3], const double b[3]) {
  const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const double w = 1.0 + d, n = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + w * w);
  sph_quat q;
  q.x = (float)(c[0] / n), q.y = (float)(c[1] / n), q.z = (float)(c[2] / n), q.w = (float)(w / n);
  return q;
}

/* A plane collider whose solid is {x : u . x > offset} (the plane shape's solid y < 0, turned so
 * its +y is -u). */
static void add_wall(sph_context* context, sph_world* world, const double u[3], double offset,
                     sph_sdf** out) {
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id id;
  const double y[3] = {0.0, 1.0, 0.0}, minus_u[3] = {-u[0], -u[1], -u[2]};
  EXPECT_OK(sph_shape_desc_init(&shape));
  shape.shape = SPH_SHAPE_PLANE;
  shape.half_extents.x = 0.2f, shape.half_extents.y = 0.05f, shape.half_extents.z = 0.2f;
  shape.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, out));
  EXPECT_OK(sph_collider_def_init(&def));
  def.sdf = *out;
  def.transform = sph_transform_identity();
  def.transform.position.x = (float)(u[0] * offset);
  def.transform.position.y = (float)(u[1] * offset);
  def.transform.position.z = (float)(u[2] * offset);
  def.transform.rotation = turn(y, minus_u);
  EXPECT_OK(sph_collider_create(world, &def, &id));
}

/* One step of 1 us without gravity: the densities it reports are those of the spawn positions. */
static void read_densities_at_rest(support_world* w) {
  EXPECT_OK(support_set_gravity_and_steps(w->world, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-6f));
  EXPECT_OK(sph_world_step(w->world, 1e-6f));
}

typedef struct layer_stats {
  double mean, lo, hi;
  uint32_t count;
} layer_stats;

static void add_sample(layer_stats* s, double v) {
  if (s->count == 0) s->lo = s->hi = v;
  s->mean += v, s->lo = fmin(s->lo, v), s->hi = fmax(s->hi, v), ++s->count;
}

/* The first layer of the FCC ball of radius 6 s cut by the plane u . x <= 0 (a lattice plane),
 * against a wall s/2 beyond it: rho / rho0 over the first-layer particles farther than h from
 * the ball's rim (their neighbourhood is the half lattice). */
static layer_stats first_layer_at_wall(const double u[3], uint32_t features) {
  const sph_world_def def = boundary_def(features, 4096);
  support_world w;
  float *ball = NULL, *kept, *x = NULL, *rho = NULL;
  uint32_t n = 0, m = 0;
  sph_sdf* sdf = NULL;
  layer_stats s = {0.0, 0.0, 0.0, 0};
  const double radius = 6.0 * kSpacing;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(support_fcc_sphere(NULL, radius, kSpacing, &ball, &n));
  kept = (float*)malloc(12 * (size_t)n);
  assert_non_null(kept);
  for (uint32_t i = 0; i < n; ++i) {
    const double d = u[0] * ball[3 * i] + u[1] * ball[3 * i + 1] + u[2] * ball[3 * i + 2];
    if (d > 1e-6) continue;
    memcpy(kept + 3 * m++, ball + 3 * i, 12);
  }
  EXPECT_OK(support_spawn(w.world, kept, NULL, m));
  add_wall(w.context, w.world, u, 0.5 * kSpacing, &sdf);
  read_densities_at_rest(&w);
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &n));
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, &n));
  for (uint32_t i = 0; i < n; ++i) {
    const double p[3] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
    const double d = u[0] * p[0] + u[1] * p[1] + u[2] * p[2];
    const double r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    if (fabs(d) > 1e-4 || r2 > (radius - w.def.kernel_radius) * (radius - w.def.kernel_radius)) continue;
    add_sample(&s, rho[i] / w.def.rest_density);
  }
  s.mean /= s.count;
  free(ball), free(kept), free(x), free(rho);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
  return s;
}

/* The calibration takes the (100) face's deficit at the first layer (fcc_lattice.h: the faces
 * miss 23.1 %, 29.3 % and 18.7 % of rho0 at h = 1.8 s), so with the feature the first layer
 * reads rho0 (1 + 0.231 - deficit): exactly (100), -6.2 % (110), +4.4 % (111). The bounds are
 * those plus 0.3 % (float sums, the map's quadrature). Without it: 1 - deficit, checked within
 * 0.5 %, so a test without a wall deficit cannot pass. */
static void test_first_layer_at_walls_of_three_orientations(void** state) {
  const double r2 = 1.0 / sqrt(2.0), r3 = 1.0 / sqrt(3.0);
  const double faces[3][3] = {{1.0, 0.0, 0.0}, {r2, r2, 0.0}, {r3, r3, r3}};
  const char* names[3] = {"(100)", "(110)", "(111)"};
  const double expected_on[3] = {1.000, 0.938, 1.044}, expected_off[3] = {0.769, 0.707, 0.813};
  (void)state;
  for (int f = 0; f < 3; ++f) {
    const layer_stats on = first_layer_at_wall(faces[f], SPH_FEATURE_BOUNDARY_DENSITY);
    const layer_stats off = first_layer_at_wall(faces[f], SPH_FEATURE_NONE);
    print_message(
        "wall along %s: first layer rho/rho0 with walls in the density %.4f [%.4f, %.4f] (%u), "
        "without %.4f\n",
        names[f], on.mean, on.lo, on.hi, on.count, off.mean);
    assert_true(on.count >= 3);
    assert_true(fabs(on.lo - expected_on[f]) <= 0.003 && fabs(on.hi - expected_on[f]) <= 0.003);
    assert_true(fabs(off.mean - expected_off[f]) <= 0.005);
  }
}

/* An FCC block from sph_world_fill_box over [0, L]^3, L = s + 9 s / sqrt 2 (ten layers, the
 * outer ones s/2 inside the faces), on a floor (the plane y < 0) or closed in a box whose cavity
 * is [0, L]^3 (an inverted collider). rho / rho0 of the particles s/2 from one wall (faces[1]:
 * on the floor, its bottom layer farther than h from the block's free sides), from two (edges,
 * faces[2]) and three (corners, faces[3]); faces[0]: those farther than h from every face (the
 * bulk). */
static void block_against_walls(int closed, uint32_t features, layer_stats faces[4]) {
  const sph_world_def def = boundary_def(features, 4096);
  const double step = kSpacing / sqrt(2.0), length = kSpacing + 9.0 * step;
  const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {length, length, length};
  support_world w;
  sph_fill_box_desc box;
  sph_sdf* sdf = NULL;
  float *x = NULL, *rho = NULL;
  uint32_t n = 0;
  double h;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  h = w.def.kernel_radius;
  EXPECT_OK(sph_fill_box_desc_init(&box));
  box.max.x = box.max.y = box.max.z = (float)length;
  EXPECT_OK(sph_world_fill_box(w.world, &box, &n));
  if (closed) {
    EXPECT_OK(support_tank_between(w.context, w.world, lo, hi, 0.01, 0.0f, &sdf, NULL));
  } else {
    const double down[3] = {0.0, -1.0, 0.0};
    add_wall(w.context, w.world, down, 0.0, &sdf);
  }
  read_densities_at_rest(&w);
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &n));
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, &n));
  memset(faces, 0, 4 * sizeof *faces);
  for (uint32_t i = 0; i < n; ++i) {
    double face = 1e9, side = 1e9;
    int first = 0; /* coordinates in a first layer (s/2 from a face) */
    for (int a = 0; a < 3; ++a) {
      const double d = fmin(x[3 * i + a], length - x[3 * i + a]);
      face = fmin(face, d);
      if (a != 1) side = fmin(side, d);
      first += d < kSpacing;
    }
    if (face > h) {
      add_sample(&faces[0], rho[i] / w.def.rest_density);
    } else if (closed && first > 0 && face < kSpacing) {
      add_sample(&faces[first], rho[i] / w.def.rest_density);
    } else if (!closed && x[3 * i + 1] < kSpacing && side > h) {
      add_sample(&faces[1], rho[i] / w.def.rest_density);
    }
  }
  for (int k = 0; k < 4; ++k)
    if (faces[k].count) faces[k].mean /= faces[k].count;
  free(x), free(rho);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

/* The floor is the (100) case of the test above: rho0 with the feature (bound 0.3 %), 23.1 %
 * low without. In the box the faces read as the floor (down to -1.6 % near an edge, where a
 * second wall is within h); edges and corners add the shares of two or three walls, where the
 * calibration (a steep share, 12 rho0 times the kernel's share beyond the wall moved 0.49 spacings
 * into the solid, fitted to a flat wall's value and slope) overcounts the overlapping quarter and
 * eighth spaces, and the sampling adds the SDF's kink along the edge (docs/physics.md, Limits):
 * measured +25 % along edges and +63 % in corners at this placement (without: -41 % and -52 %). Such
 * particles are pushed off the corner at the first steps; settled, the tank below reads at most +2.5 %.
 * Bounds 0.3 % (faces) and 0.4 % around the measured ranges. The bulk reads rho0 either way (0.1 %: the
 * lattice's own calibration). */
static void test_block_on_a_floor_and_in_a_box(void** state) {
  const char* names[4] = {"bulk", "faces", "edges", "corners"};
  const double expected_on[4][2] = {{1.0, 1.0}, {0.9843, 1.0000}, {1.2435, 1.2506}, {1.6334, 1.6334}};
  const double expected_off[4] = {1.0, 0.768, 0.593, 0.476};
  (void)state;
  for (int closed = 0; closed < 2; ++closed) {
    layer_stats on[4], off[4];
    block_against_walls(closed, SPH_FEATURE_BOUNDARY_DENSITY, on);
    block_against_walls(closed, SPH_FEATURE_NONE, off);
    for (int k = 0; k < (closed ? 4 : 2); ++k) {
      const double bound = k == 0 ? 0.001 : 0.003 + (k > 1 ? 0.001 : 0.0);
      print_message("block %s, %s: rho/rho0 %.4f [%.4f, %.4f] (%u) with walls in the density, %.4f without\n",
                    closed ? "in a box" : "on a floor", names[k], on[k].mean, on[k].lo, on[k].hi, on[k].count,
                    off[k].mean);
      assert_true(on[k].count >= 4);
      if (getenv("BD_MEASURE")) continue;
      assert_true(on[k].lo >= expected_on[k][0] - bound && on[k].hi <= expected_on[k][1] + bound);
      assert_true(fabs(off[k].mean - expected_off[k]) <= (k == 0 ? 0.007 : 0.005) || getenv("BD_MEASURE"));
    }
  }
}

/* A hydrostatic tank: water at rest in a closed box (support_fcc_box's lattice, 10 x 14 x 10
 * layers of step 1 cm), 1.2 s under gravity at the default viscosity and stiffness, pressures
 * averaged over the last 0.4 s. Near the walls (within h of the floor, and within h of a side
 * wall in the middle third of the depth) each particle's pressure is compared with rho0 g d, d
 * its depth below the top of the fluid (the top layer plus half a step): the mean of
 * p / (rho0 g d) - 1 over those particles. Without the walls' share they read low by the
 * summation's deficit (the EOS clamps it to zero pressure at rest density); with it they read
 * nearer the hydrostatic value, a little high: measured +5.2 % at the floor (-48 % without) and
 * +3.1 % at the side walls away from edges (-77 % without). The hydrostatic signal is small in
 * density at the default stiffness (k = 100: 1.4 % of rho0 at the floor, 0.7 % at mid-depth), so
 * a bias of a twentieth of a percent of density near the walls shows as 5 % of the pressure.
 * Bounds: closer than without (the criterion), and 10 % at both; the tank must settle
 * (kinetic energy below 2 mJ at the end, measured 0.18 mJ, 0.14-0.28 mJ over 10 runs with the
 * lattice perturbed by 1e-7 m; with the wall's pressure mirrored, 2 p / rho^2, it kept sloshing at
 * 0.3-0.8 J, and with a wall force that was not the gradient of the sampled share it ended
 * between 0.5 mJ and 0.24 J by the rounding) and nothing may fall through the floor. The walls
 * stand spacing/2 beyond the lattice's outer layers, where the calibration puts a first layer at
 * rest: at step/2 (0.35 spacings) the lattice starts compressed against them (up to 1.26 rho0 at
 * the faces, 2.1 in the corners) with twice the water's potential energy to shed. */
static void tank_wall_pressure(uint32_t features, double* floor_error, double* side_error, float* lowest,
                               double* kinetic) {
  const uint32_t layers[3] = {10, 14, 10};
  const double step = 0.01, origin[3] = {0.0, 0.0, 0.0};
  const double width = layers[0] * step, depth = layers[1] * step;
  /* The lattice's outer layers lie step/2 inside [0, width]; the walls go spacing/2 (step/sqrt(2))
   * beyond them, where the calibration puts a resting first layer. */
  const double gap = 0.5 * step * (sqrt(2.0) - 1.0);
  const double tank_min[3] = {-gap, -gap, -gap}, tank_max[3] = {width + gap, 2.0 * depth, width + gap};
  sph_world_def def = boundary_def(features, 0);
  sph_world_params params;
  support_world w;
  sph_sdf* sdf = NULL;
  float *lattice = NULL, *x = NULL, *p = NULL;
  uint32_t n = 0, m = 0;
  double *sum, top = -1e9, h, rho0;
  const double g = 9.81;
  int samples = 0;
  EXPECT_OK(support_fcc_box(layers, step, origin, &lattice, &n));
  def.capacity = n;
  def.particle_spacing = (float)(step * sqrt(2.0));
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  sph_world_params_init(&params);
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  EXPECT_OK(sph_world_set_params(w.world, &params));
  EXPECT_OK(support_tank_between(w.context, w.world, tank_min, tank_max, 0.5 * step, 0.0f, &sdf, NULL));
  EXPECT_OK(support_spawn(w.world, lattice, NULL, n));
  for (uint32_t i = 0; i < n; ++i) top = fmax(top, lattice[3 * i + 1]);
  top += 0.5 * step;
  h = w.def.kernel_radius, rho0 = w.def.rest_density;
  sum = (double*)calloc(n, sizeof(double));
  assert_non_null(sum);
  *lowest = 1e9f;
  for (int frame = 0; frame < 60; ++frame) {
    EXPECT_OK(sph_world_step(w.world, 0.02f));
    if (frame < 40) continue;
    free(p);
    p = NULL;
    EXPECT_OK(support_copy_by_id(w.world, SPH_ATTRIBUTE_PRESSURE, (void**)&p, &m));
    for (uint32_t i = 0; i < m; ++i) sum[i] += p[i];
    ++samples;
  }
  EXPECT_OK(support_copy_by_id(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &m));
  EXPECT_OK(support_kinetic_energy(w.world, w.mass, kinetic));
  {
    double f = 0.0, s = 0.0;
    uint32_t nf = 0, ns = 0;
    for (uint32_t i = 0; i < m; ++i) {
      /* y, sx, sz: distances from the floor and the side walls */
      const double y = x[3 * i + 1] + gap, d = top - x[3 * i + 1], hydro = rho0 * g * d;
      const double sx = fmin(x[3 * i], width - x[3 * i]) + gap,
                   sz = fmin(x[3 * i + 2], width - x[3 * i + 2]) + gap;
      const double side = fmin(sx, sz), other = fmax(sx, sz); /* other > h: one side wall, no edge */
      const double rel = sum[i] / samples / hydro - 1.0;
      *lowest = fminf(*lowest, (float)y);
      if (y < h && side > h) f += rel, ++nf;
      if (side < h && other > h && d > depth / 3.0 && d < 2.0 * depth / 3.0) s += rel, ++ns;
    }
    assert_true(nf > 0 && ns > 0);
    *floor_error = f / nf;
    *side_error = s / ns;
  }
  free(sum), free(lattice), free(x), free(p);
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
}

static void test_hydrostatic_tank_near_walls(void** state) {
  double floor_on, side_on, floor_off, side_off, ke_on, ke_off;
  float lowest_on, lowest_off;
  (void)state;
  tank_wall_pressure(SPH_FEATURE_BOUNDARY_DENSITY, &floor_on, &side_on, &lowest_on, &ke_on);
  tank_wall_pressure(SPH_FEATURE_NONE, &floor_off, &side_off, &lowest_off, &ke_off);
  print_message(
      "hydrostatic tank, p / (rho0 g d) - 1 near the floor: %+.1f %% with walls in the density, "
      "%+.1f %% without; near the side walls: %+.1f %% / %+.1f %%; lowest particle %.4f / %.4f m above the "
      "floor; "
      "kinetic energy at the end %.2g / %.2g J\n",
      100.0 * floor_on, 100.0 * floor_off, 100.0 * side_on, 100.0 * side_off, lowest_on, lowest_off, ke_on,
      ke_off);
  assert_true(fabs(floor_on) < fabs(floor_off) && fabs(floor_on) <= 0.10);
  assert_true(fabs(side_on) < fabs(side_off) && fabs(side_on) <= 0.10);
  assert_true(ke_on < 2e-3);
  assert_true(lowest_on > -0.0005f); /* no particle below the floor */
}

/* A kinematic box (a solid collider 4 cm thick) moved at 1 m/s through water in a channel (an
 * inverted box) for 0.1 s, with walls in the density: the paddle's pressure pushes the water
 * ahead of it (its mean x velocity turns positive) and no particle ends inside the paddle, within
 * a quarter spacing of its face after every frame (the collision response's safeguard, which the
 * wall's pressure must not defeat by, say, flinging particles through). */
static void test_kinematic_box_pushes_without_leaking(void** state) {
  const sph_world_def def = boundary_def(SPH_FEATURE_BOUNDARY_DENSITY, 8000);
  const float half_thickness = 0.02f, speed = 1.0f;
  support_world w;
  sph_shape_desc d;
  sph_sdf *channel = NULL, *paddle = NULL;
  sph_collider_def cdef;
  sph_collider_id paddle_id, channel_id;
  sph_fill_box_desc fill;
  float paddle_x = -0.3f, *x = NULL, *v = NULL;
  uint32_t n = 0, m = 0;
  double mean_vx = 0.0;
  (void)state;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(support_set_gravity_and_steps(w.world, 0.0f, -9.81f, 0.0f, 1e-6f, 1e-3f));
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
  d.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(w.context, &d, &paddle));
  cdef.sdf = paddle;
  cdef.flags = 0;
  cdef.transform.position.x = paddle_x;
  EXPECT_OK(sph_collider_create(w.world, &cdef, &paddle_id));
  EXPECT_OK(sph_fill_box_desc_init(&fill));
  fill.min.x = -0.27f, fill.min.y = 0.0f, fill.min.z = -0.06f;
  fill.max.x = 0.1f, fill.max.y = 0.1f, fill.max.z = 0.06f;
  EXPECT_OK(sph_world_fill_box(w.world, &fill, &n));
  for (int frame = 0; frame < 10; ++frame) {
    sph_transform target = sph_transform_identity();
    paddle_x += speed * 0.01f;
    target.position.x = paddle_x, target.position.y = 0.2f;
    EXPECT_OK(sph_collider_set_target_transform(w.world, paddle_id, &target));
    EXPECT_OK(sph_world_step(w.world, 0.01f));
    free(x);
    x = NULL;
    EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_POSITION, (void**)&x, &m));
    assert_int_equal(m, n);
    for (uint32_t i = 0; i < m; ++i) {
      const int inside = fabsf(x[3 * i] - paddle_x) < half_thickness - 0.25f * kSpacing &&
                         fabsf(x[3 * i + 1] - 0.2f) < 0.3f && fabsf(x[3 * i + 2]) < 0.1f;
      assert_false(inside);
    }
  }
  EXPECT_OK(support_copy(w.world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &m));
  for (uint32_t i = 0; i < m; ++i) mean_vx += v[3 * i];
  mean_vx /= m;
  print_message(
      "kinematic box at %.1f m/s: water's mean x velocity %.3f m/s after 0.1 s, %u particles, none inside\n",
      speed, mean_vx, m);
  assert_true(mean_vx > 0.05);
  free(x), free(v);
  EXPECT_OK(sph_sdf_destroy(channel));
  EXPECT_OK(sph_sdf_destroy(paddle));
  EXPECT_OK(support_world_close(&w));
}

/* A ball SDF of n^3 voxels (2 cm, centred) of radius `radius`, as a grid desc's data. */
static float* ball_grid(uint32_t n, float radius) {
  float* d = (float*)malloc(sizeof(float) * n * n * n);
  assert_non_null(d);
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        const float c = 0.5f * (float)(n - 1);
        const float x = 0.02f * ((float)i - c), y = 0.02f * ((float)j - c), z = 0.02f * ((float)k - c);
        d[i + n * (j + n * k)] = sqrtf(x * x + y * y + z * z) - radius;
      }
  return d;
}

static sph_sdf* ball_asset(sph_context* context, uint32_t n, const float* data) {
  sph_sdf_desc desc;
  sph_sdf* sdf = NULL;
  const float c = -0.01f * (float)(n - 1);
  EXPECT_OK(sph_sdf_desc_init(&desc));
  desc.distance.struct_size = sizeof desc.distance;
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = n;
  desc.distance.index_to_local[0] = desc.distance.index_to_local[5] = desc.distance.index_to_local[10] =
      0.02f;
  desc.distance.index_to_local[3] = desc.distance.index_to_local[7] = desc.distance.index_to_local[11] = c;
  desc.distance.data = data;
  EXPECT_OK(sph_sdf_create(context, &desc, &sdf));
  return sdf;
}

/* The densities of a slab of water (one FCC layer block) resting on a ball collider whose asset
 * holds `data`, or, with `update`, first `data` and then `update` written by sph_sdf_update
 * after one step: the update must recompute the map, so the densities equal those of a world made
 * with the updated data from the start (same particles, same map): compared to 1e-6 relative
 * (float rounding of the one step's motion, measured 0). */
static float* densities_on_ball(const float* data, const float* update, int halves, uint32_t n,
                                uint32_t* count) {
  const sph_world_def def = boundary_def(SPH_FEATURE_BOUNDARY_DENSITY, 4096);
  support_world w;
  sph_sdf* sdf;
  sph_collider_def cdef;
  sph_collider_id id;
  sph_fill_box_desc fill;
  float* rho = NULL;
  EXPECT_OK(support_world_open(&w, sph_test_backend(), &def, NULL));
  EXPECT_OK(support_set_gravity_and_steps(w.world, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-6f));
  sdf = ball_asset(w.context, n, data);
  EXPECT_OK(sph_collider_def_init(&cdef));
  cdef.sdf = sdf;
  cdef.transform = sph_transform_identity();
  EXPECT_OK(sph_collider_create(w.world, &cdef, &id));
  EXPECT_OK(sph_fill_box_desc_init(&fill));
  fill.min.x = -0.1f, fill.min.y = 0.105f, fill.min.z = -0.1f;
  fill.max.x = 0.1f, fill.max.y = 0.16f, fill.max.z = 0.1f;
  EXPECT_OK(sph_world_fill_box(w.world, &fill, count));
  if (update && halves) {
    /* The lower half in z, a step, then the upper half: two changes of part of the grid each (on
     * the CPU each recomputes only its reach of the map). */
    float* part = (float*)malloc(sizeof(float) * n * n * n);
    assert_non_null(part);
    for (uint32_t half = 0; half < 2; ++half) {
      const uint32_t z0 = half ? n / 2 : 0, depth = half ? n - n / 2 : n / 2;
      const uint32_t origin[3] = {0, 0, z0}, size[3] = {n, n, depth};
      memcpy(part, update + (size_t)n * n * z0, sizeof(float) * n * n * depth);
      EXPECT_OK(sph_world_step(w.world, 1e-6f));
      EXPECT_OK(sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, part, SPH_MEMORY_HOST));
    }
    free(part);
  } else if (update) {
    const uint32_t origin[3] = {0, 0, 0}, size[3] = {n, n, n};
    EXPECT_OK(sph_world_step(w.world, 1e-6f));
    EXPECT_OK(sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, update, SPH_MEMORY_HOST));
  }
  EXPECT_OK(sph_world_step(w.world, 1e-6f));
  EXPECT_OK(support_copy_by_id(w.world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, count));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
  return rho;
}

static void test_updated_asset_recomputes_its_map(void** state) {
  const uint32_t n = 21;
  float* small = ball_grid(n, 0.08f);
  float* large = ball_grid(n, 0.1f);
  uint32_t count = 0, c2 = 0, c3 = 0;
  float* before = densities_on_ball(small, NULL, 0, n, &count);
  float* updated = densities_on_ball(small, large, 0, n, &c2);
  float* fresh = densities_on_ball(large, NULL, 0, n, &c3);
  uint32_t c4 = 0;
  float* in_halves = densities_on_ball(small, large, 1, n, &c4);
  double worst_halves = 0.0;
  double worst = 0.0, changed = 0.0;
  (void)state;
  assert_int_equal(count, c2);
  assert_int_equal(count, c3);
  assert_int_equal(count, c4);
  for (uint32_t i = 0; i < count; ++i) {
    worst = fmax(worst, fabs(updated[i] / fresh[i] - 1.0));
    worst_halves = fmax(worst_halves, fabs(in_halves[i] / fresh[i] - 1.0));
    changed = fmax(changed, fabs(updated[i] / before[i] - 1.0));
  }
  print_message(
      "asset updated by sph_sdf_update: densities within %.2e of a fresh asset's (%.2e updated in "
      "two halves); up to %.1f %% from the old map's\n",
      worst, worst_halves, 100.0 * changed);
  assert_true(worst <= 1e-6);
  assert_true(worst_halves <= 1e-6);
  /* The ball grew into the slab's kernel support: its nearest particle lies about 0.69 h from the
   * grown ball's moved surface (radius 0.1 m less delta), where a ball of 2.5 h holds a share of
   * about 0.0018-0.0023 of the kernel (test_boundary_map.cpp's brute force at 0.71 h, radius 2.8 h),
   * 2.2-2.8 % of rho0 at K = 12 rho0. Measured 2.0 % with a solid's map correcting the distance
   * (boundary_map.h; its added share, before session 16, read more than 5 % on these 2 cm voxels). */
  assert_true(changed > 0.01);
  free(small), free(large), free(before), free(updated), free(fresh), free(in_halves);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_first_layer_at_walls_of_three_orientations),
      cmocka_unit_test(test_block_on_a_floor_and_in_a_box),
      cmocka_unit_test(test_hydrostatic_tank_near_walls),
      cmocka_unit_test(test_kinematic_box_pushes_without_leaking),
      cmocka_unit_test(test_updated_asset_recomputes_its_map),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
