// SPDX-License-Identifier: MIT
/* Extremes of the input: 0, 1 and 2 particles; all particles at one point; particles 1e6 m
 * from the origin and at 1e30 m; 1x1x1 and very large SDFs; spacings near float precision;
 * capacity exhausted. Each ends in a specific error with a message that names the problem (and
 * an unchanged world) or in a stated stable state. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "extremes_util.h"

static uint32_t count_of(const ext_world* w) {
  uint32_t n = 0;
  EXT_OK(sph_world_get_particle_count(w->world, &n));
  return n;
}

static void expect_all_finite(const ext_world* w) {
  uint32_t n = 0, i;
  float* x = (float*)ext_copy(w->world, SPH_ATTRIBUTE_POSITION, &n);
  float* v = (float*)ext_copy(w->world, SPH_ATTRIBUTE_VELOCITY, &n);
  float* rho = (float*)ext_copy(w->world, SPH_ATTRIBUTE_DENSITY, &n);
  for (i = 0; i < 3 * n; ++i) assert_true(isfinite(x[i]) && isfinite(v[i]));
  for (i = 0; i < n; ++i) assert_true(isfinite(rho[i]));
  free(x);
  free(v);
  free(rho);
}

/* An empty world steps: the frame completes, nothing is simulated, statistics are zero. */
static void test_zero_particles(void** state) {
  ext_world w;
  sph_stats st;
  (void)state;
  ext_open(&w, 16, 0.02f);
  EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  assert_int_equal(st.particle_count, 0);
  assert_true(st.max_speed == 0.0f);
  assert_true(fabs(st.frame_time - 1.0f / 60.0f) <= 1e-7);
  ext_close(&w);
}

/* The density's self term w0 (src/physics/density.h): rho0 / m minus the sum of the scaled
 * W_spiky over the FCC lattice's neighbours at `spacing`, so that the lattice sits at rho0. The
 * scale (fcc_spiky_scale) makes the lattice's first moment of grad W exact:
 * (m / rho0) sum_j x_j^2 / r_j |W'(r_j)| = 1. Computed here in double from the definitions. */
static double density_self_weight(double spacing, double h, double rho0, double mass) {
  const double step = spacing / sqrt(2.0);
  const int n = (int)ceil(h / step) + 1;
  const double pi = 3.14159265358979;
  double sum = 0.0, moment = 0.0;
  for (int k = -n; k <= n; ++k)
    for (int j = -n; j <= n; ++j)
      for (int i = -n; i <= n; ++i) {
        double r, x;
        if (((i + j + k) % 2 + 2) % 2 != 0 || (i == 0 && j == 0 && k == 0)) continue;
        r = step * sqrt((double)(i * i + j * j + k * k));
        if (r >= h) continue;
        x = step * i;
        sum += 15.0 / (pi * pow(h, 6.0)) * (h - r) * (h - r) * (h - r);
        moment += 45.0 / (pi * pow(h, 6.0)) * (h - r) * (h - r) * x * x / r;
      }
  return rho0 / mass - sum / (mass / rho0 * moment);
}

/* One particle has no neighbours: density m w0, the self term alone (below rho0, so no
 * pressure), and it falls freely. Symplectic Euler gives v = -g t exactly up to rounding, and y
 * lags the exact y0 - g t^2 / 2 by at most g t dt_max / 2 (each step uses the new velocity). */
static void test_one_particle(void** state) {
  ext_world w;
  const float x0[3] = {0.0f, 1.0f, 0.0f};
  float x[3], v[3], rho;
  sph_stats st;
  double t;
  (void)state;
  ext_open(&w, 16, 0.02f);
  ext_spawn(&w, x0, NULL, 1);
  EXPECT_OK(sph_world_step(w.world, 0.1f));
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  t = st.simulated_time;
  EXT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_POSITION, x, sizeof x, 0, 0, 1, NULL));
  EXT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 1, NULL));
  EXT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_DENSITY, &rho, sizeof rho, 0, 0, 1, NULL));
  assert_true(fabs(v[1] + EXT_G * t) <= 1e-5 * EXT_G * t);
  assert_true(v[0] == 0.0f && v[2] == 0.0f);
  assert_true(x[1] <= 1.0 - 0.5 * EXT_G * t * t + 1e-6);
  assert_true(x[1] >= 1.0 - 0.5 * EXT_G * t * t - 0.5 * EXT_G * t * st.dt_max - 1e-6);
  {
    const double h = w.def.kernel_radius;
    const double expected = w.mass * density_self_weight(0.02, h, 1000.0, w.mass);
    assert_true(fabs(rho - expected) <= 1e-5 * expected);
  }
  ext_close(&w);
}

/* Two particles approaching each other at 0.5 m/s, no gravity: their density stays below rho0
 * (m (w0 + W_spiky(0)) = 0.94 rho0 at most), so only viscosity acts, whose pair terms are equal and opposite:
 * the total momentum stays zero to float rounding and the relative speed can only fall. */
static void test_two_particles(void** state) {
  ext_world w;
  const float x0[6] = {-0.01f, 0.0f, 0.0f, 0.01f, 0.0f, 0.0f};
  const float v0[6] = {0.25f, 0.0f, 0.0f, -0.25f, 0.0f, 0.0f};
  float v[6];
  int frame;
  float relative = 0.5f;
  (void)state;
  ext_open(&w, 16, 0.02f);
  w.params.gravity.y = 0.0f;
  ext_set_params(&w);
  ext_spawn(&w, x0, v0, 2);
  for (frame = 0; frame < 10; ++frame) {
    float now;
    EXPECT_OK(sph_world_step(w.world, 0.01f));
    EXT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 2, NULL));
    assert_true(fabsf(v[0] + v[3]) <= 1e-6f && fabsf(v[1] + v[4]) <= 1e-6f && fabsf(v[2] + v[5]) <= 1e-6f);
    now = fabsf(v[0] - v[3]);
    assert_true(now <= relative * (1.0f + 1e-6f));
    relative = now;
  }
  expect_all_finite(&w);
  ext_close(&w);
}

/* 64 particles at one point above a floor: the pressure gradient vanishes at r = 0 (its direction
 * is undefined there), so the lump stays one point, falls, and rests on the floor. Stable state:
 * all finite, none lost, density m (w0 + 63 W_spiky(0)), speed at most the free-fall speed from 0.1 m, and
 * the lump no deeper in the floor than half a spacing. */
static void test_all_particles_at_one_point(void** state) {
  ext_world w;
  ext_tank t;
  float x[3 * 64];
  uint32_t n = 0, i;
  int frame;
  float *p, *v, *rho;
  const float v_free = sqrtf(2.0f * EXT_G * 0.1f);
  (void)state;
  memset(&t, 0, sizeof t);
  t.hx = t.hy = t.hz = 0.1f;
  t.column_width = 0.0f;
  ext_open(&w, 128, 0.02f);
  {
    sph_shape_desc shape;
    sph_collider_def collider;
    sph_shape_desc_init(&shape);
    shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = 0.1f;
    EXT_OK(sph_sdf_create_shape(w.context, &shape, &t.sdf));
    sph_collider_def_init(&collider);
    collider.sdf = t.sdf;
    collider.flags = SPH_COLLIDER_FLAG_INVERTED;
    collider.transform.position.y = 0.1f;
    EXT_OK(sph_collider_create(w.world, &collider, &t.collider));
  }
  for (i = 0; i < 64; ++i) {
    x[3 * i] = 0.0f;
    x[3 * i + 1] = 0.1f;
    x[3 * i + 2] = 0.0f;
  }
  ext_spawn(&w, x, NULL, 64);
  for (frame = 0; frame < 20; ++frame) EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  expect_all_finite(&w);
  p = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  v = (float*)ext_copy(w.world, SPH_ATTRIBUTE_VELOCITY, &n);
  rho = (float*)ext_copy(w.world, SPH_ATTRIBUTE_DENSITY, &n);
  assert_int_equal(n, 64);
  for (i = 0; i < n; ++i) {
    const float speed =
        sqrtf(v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2]);
    assert_true(speed <= v_free);
    assert_true(p[3 * i + 1] >= -0.01f);
    assert_true(fabsf(rho[i] - rho[0]) <= 1e-6f * rho[0]);
  }
  print_message("  one point: y %.4f m, density %.0f kg/m^3\n", p[1], rho[0]);
  free(p);
  free(v);
  free(rho);
  ext_tank_destroy(&w, &t);
  ext_close(&w);
}

/* Runs a block (a 5 x 5 x 5 spacing FCC fill at the origin, shifted by `offset` along x) with
 * small deterministic random velocities and no gravity for `frames` frames; returns positions
 * relative to the offset, by id. */
static float* run_block(float spacing, float offset, int frames, uint32_t* out_n) {
  ext_world w;
  sph_fill_box_desc fill;
  uint32_t n = 0, i;
  uint64_t seed = 12345u;
  float *x, *v, *by_id;
  uint32_t* ids;
  ext_open(&w, 512, spacing);
  w.params.gravity.y = 0.0f;
  w.params.stiffness = 1e4f;
  ext_set_params(&w);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 5.0f * spacing;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  x = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  ext_close(&w);
  v = (float*)malloc(12 * (size_t)n);
  assert_non_null(v);
  for (i = 0; i < 3 * n; ++i) v[i] = (float)(support_random(&seed) - 0.5) * 0.01f * spacing;
  for (i = 0; i < n; ++i) x[3 * i] += offset;
  ext_open(&w, 512, spacing);
  w.params.gravity.y = 0.0f;
  w.params.stiffness = 1e4f;
  ext_set_params(&w);
  ext_spawn(&w, x, v, n);
  free(x);
  free(v);
  while (frames-- > 0) EXPECT_OK(sph_world_step(w.world, 0.02f));
  x = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  ids = (uint32_t*)ext_copy(w.world, SPH_ATTRIBUTE_ID, &n);
  by_id = (float*)malloc(12 * (size_t)n);
  assert_non_null(by_id);
  for (i = 0; i < n; ++i) {
    by_id[3 * ids[i]] = x[3 * i] - offset;
    by_id[3 * ids[i] + 1] = x[3 * i + 1];
    by_id[3 * ids[i] + 2] = x[3 * i + 2];
  }
  free(x);
  free(ids);
  ext_close(&w);
  *out_n = n;
  return by_id;
}

/* 1e6 m from the origin float32 steps are 0.0625 m. With a 2 cm spacing that is three times the
 * spacing: refused, naming the bound (65536 spacings) and float precision. With a 16 m spacing
 * (bound 1.05e6 m) the steps are 1/256 of the spacing, and the same block run at 1e6 m and at
 * the origin agree to 1 % of the spacing after 5 frames. */
static void test_far_from_origin_1e6(void** state) {
  ext_world w;
  sph_fill_box_desc fill;
  uint32_t n_far = 0, n_near = 0, i;
  float *far, *near;
  float worst = 0.0f;
  (void)state;
  ext_open(&w, 512, 0.02f);
  sph_fill_box_desc_init(&fill);
  fill.min.x = 1e6f;
  fill.max.x = 1e6f + 0.1f;
  fill.max.y = fill.max.z = 0.1f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "65536 particle spacings",
               sph_world_fill_box(w.world, &fill, NULL));
  assert_non_null(strstr(sph_get_last_error(), "float32"));
  assert_int_equal(count_of(&w), 0);
  ext_close(&w);

  near = run_block(16.0f, 0.0f, 5, &n_near);
  far = run_block(16.0f, 1e6f, 5, &n_far);
  assert_int_equal(n_far, n_near);
  for (i = 0; i < 3 * n_far; ++i) {
    assert_true(isfinite(far[i]));
    worst = fmaxf(worst, fabsf(far[i] - near[i]));
  }
  print_message("  1e6 m: %u particles, worst difference to the run at the origin %.4f m (spacing 16 m)\n",
                n_far, worst);
  assert_true(worst <= 0.01f * 16.0f);
  free(far);
  free(near);
}

/* A step may carry a particle beyond the positions' reach (65536 spacings: 1310.72 m at 2 cm);
 * nothing stops free flight. The world goes on: steps, a checkpoint's save and load; a write of a
 * range that gives such a particle its own position back succeeds (a read-modify-write of every
 * position), while moving it, or another particle, beyond the bound is refused and changes
 * nothing. */
static void test_step_carries_particle_beyond_reach(void** state) {
  ext_world w;
  const float positions[6] = {0.0f, 0.0f, 0.0f, 1300.0f, 0.0f, 0.0f};
  const float velocities[6] = {0.0f, 0.0f, 0.0f, 2000.0f, 0.0f, 0.0f};
  const float bound = 65536.0f * 0.02f;
  float p[6], moved[6];
  uint32_t far = 2, near, i, written = 0;
  capi_snapshot before;
  sph_world* loaded = NULL;
  void* buffer;
  uint64_t size = 0;
  (void)state;
  ext_open(&w, 8, 0.02f);
  ext_spawn(&w, positions, velocities, 2);
  for (i = 0; i < 3; ++i) EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  EXPECT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_POSITION, p, sizeof p, 0, 0, 2, &written));
  assert_int_equal(written, 2);
  for (i = 0; i < 2; ++i)
    if (fabsf(p[3 * i]) > bound) far = i;
  assert_true(far < 2); /* the premise: a step carried it past the bound */
  near = 1 - far;
  print_message("  particle at x = %.2f m, beyond the bound %.2f m\n", (double)p[3 * far], (double)bound);

  /* Every position back, the near one moved by 1 cm: accepted. */
  memcpy(moved, p, sizeof p);
  moved[3 * near + 1] += 0.01f;
  EXPECT_OK(sph_world_set_attribute(w.world, SPH_ATTRIBUTE_POSITION, moved, sizeof moved, 0, 0, 2));
  EXPECT_OK(sph_world_copy_attribute(w.world, SPH_ATTRIBUTE_POSITION, p, sizeof p, 0, 0, 2, NULL));
  assert_memory_equal(p, moved, sizeof p);

  /* The far particle moved by 1 m, or the near one sent beyond the bound: refused, unchanged. */
  capi_snapshot_take(w.world, &before);
  memcpy(moved, p, sizeof p);
  moved[3 * far] += 1.0f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, far == 0 ? "src[0]" : "src[1]",
               sph_world_set_attribute(w.world, SPH_ATTRIBUTE_POSITION, moved, sizeof moved, 0, 0, 2));
  assert_non_null(strstr(sph_get_last_error(), "65536 particle spacings"));
  EXPECT_UNCHANGED(w.world, &before);
  memcpy(moved, p, sizeof p);
  moved[3 * near] = p[3 * far];
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, near == 0 ? "src[0]" : "src[1]",
               sph_world_set_attribute(w.world, SPH_ATTRIBUTE_POSITION, moved, sizeof moved, 0, 0, 2));
  EXPECT_UNCHANGED(w.world, &before);

  /* A checkpoint keeps it, and the loaded world steps. */
  EXPECT_OK(sph_world_save(w.world, NULL, 0, &size));
  buffer = malloc((size_t)size);
  assert_non_null(buffer);
  EXPECT_OK(sph_world_save(w.world, buffer, size, &size));
  EXPECT_OK(sph_world_load(w.context, buffer, size, &loaded));
  EXPECT_OK(sph_world_copy_attribute(loaded, SPH_ATTRIBUTE_POSITION, moved, sizeof moved, 0, 0, 2, NULL));
  assert_memory_equal(moved, p, sizeof p);
  EXPECT_OK(sph_world_step(loaded, 1.0f / 60.0f));
  EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  sph_world_destroy(loaded);
  free(buffer);
  ext_close(&w);
}

/* Positions at 1e30 m: spawn, box and sphere fills are refused with INVALID_ARGUMENT naming the
 * argument, and the world is unchanged. */
static void test_position_1e30_is_refused(void** state) {
  ext_world w;
  const float ok[3] = {0.0f, 0.1f, 0.0f};
  float x[6] = {0.0f, 0.0f, 0.0f, 1e30f, 0.0f, 0.0f};
  sph_spawn_desc d;
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  capi_snapshot before;
  (void)state;
  ext_open(&w, 64, 0.02f);
  ext_spawn(&w, ok, NULL, 1);
  EXPECT_OK(sph_world_step(w.world, 0.01f));
  capi_snapshot_take(w.world, &before);
  sph_spawn_desc_init(&d);
  d.count = 2;
  d.positions = x;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "positions[1]", sph_world_spawn(w.world, &d, NULL));
  assert_non_null(strstr(sph_get_last_error(), "float32"));
  EXPECT_UNCHANGED(w.world, &before);
  sph_fill_box_desc_init(&box);
  box.min.x = 1e30f;
  box.max.x = 1e30f + 1e24f;
  box.max.y = box.max.z = 0.05f;
  assert_true(sph_world_fill_box(w.world, &box, NULL) < 0); /* capacity or position: an error */
  EXPECT_UNCHANGED(w.world, &before);
  sph_fill_sphere_desc_init(&sphere);
  sphere.center.y = -1e30f;
  sphere.radius = 0.03f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc", sph_world_fill_sphere(w.world, &sphere, NULL));
  EXPECT_UNCHANGED(w.world, &before);
  ext_close(&w);
}

/* A 1x1x1 SDF: one sample (-0.5 at the origin); outside its box the distance grows with the
 * distance to it, so it acts as a sphere of radius 0.5 m. Particles dropped on it, and one
 * started exactly at its centre (where the gradient vanishes), stay finite and none ends up
 * deeper than half a spacing inside it. */
static void test_sdf_1x1x1(void** state) {
  ext_world w;
  sph_sdf_desc desc;
  sph_sdf* sdf = NULL;
  sph_collider_def collider;
  sph_collider_id id;
  const float value = -0.5f;
  uint32_t dims[3];
  float x[3 * 5] = {0.0f, 0.6f, 0.0f, 0.05f, 0.7f, 0.0f,  0.3f, 0.5f,
                    0.1f, 0.0f, 0.0f, 0.0f,  0.0f, 0.55f, 0.2f};
  uint32_t n = 0, i;
  float* p;
  int frame;
  (void)state;
  ext_open(&w, 16, 0.02f);
  sph_sdf_desc_init(&desc);
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 1;
  desc.distance.components = 1;
  desc.distance.data = &value;
  EXT_OK(sph_sdf_create(w.context, &desc, &sdf));
  EXT_OK(sph_sdf_get_dims(sdf, dims));
  assert_true(dims[0] == 1 && dims[1] == 1 && dims[2] == 1);
  sph_collider_def_init(&collider);
  collider.sdf = sdf;
  EXT_OK(sph_collider_create(w.world, &collider, &id));
  ext_spawn(&w, x, NULL, 5);
  for (frame = 0; frame < 30; ++frame) EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  expect_all_finite(&w);
  p = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  assert_int_equal(n, 5);
  for (i = 0; i < n; ++i) {
    const float r = sqrtf(p[3 * i] * p[3 * i] + p[3 * i + 1] * p[3 * i + 1] + p[3 * i + 2] * p[3 * i + 2]);
    print_message("  1x1x1: particle at radius %.4f m\n", r);
    assert_true(r >= 0.5f - 0.01f);
  }
  free(p);
  EXT_OK(sph_collider_destroy(w.world, id));
  EXT_OK(sph_sdf_destroy(sdf));
  ext_close(&w);
}

/* Very large SDFs. More than 2^31 voxels is CAPACITY before any data is read (the data pointer
 * here holds one float); an analytic shape of 2e6 m at 1 cm voxels (8e24 voxels) likewise. A
 * grid of huge voxels (a 200 km box of 10 km voxels as the floor) works: particles dropped on
 * its top face rest on it, no deeper than half a spacing. */
static void test_sdf_very_large(void** state) {
  ext_world w;
  sph_sdf_desc desc;
  sph_shape_desc shape;
  sph_sdf* sdf = NULL;
  sph_collider_def collider;
  sph_collider_id id;
  const float one = 1.0f;
  float x[3 * 3] = {0.0f, 0.1f, 0.0f, 0.3f, 0.2f, 0.0f, -5.0f, 0.05f, 7.0f};
  uint32_t n = 0, i;
  float* p;
  int frame;
  (void)state;
  ext_open(&w, 16, 0.02f);
  sph_sdf_desc_init(&desc);
  desc.distance.dims[0] = 2048;
  desc.distance.dims[1] = 2048;
  desc.distance.dims[2] = 1024;
  desc.distance.components = 1;
  desc.distance.data = &one;
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "2^31", sph_sdf_create(w.context, &desc, &sdf));
  assert_null(sdf);
  sph_shape_desc_init(&shape);
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = 1e6f;
  shape.voxel_size = 0.01f;
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "voxel", sph_sdf_create_shape(w.context, &shape, &sdf));
  assert_null(sdf);
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = 1e5f;
  shape.voxel_size = 1e4f;
  EXT_OK(sph_sdf_create_shape(w.context, &shape, &sdf));
  sph_collider_def_init(&collider);
  collider.sdf = sdf;
  collider.transform.position.y = -1e5f;
  EXT_OK(sph_collider_create(w.world, &collider, &id));
  ext_spawn(&w, x, NULL, 3);
  for (frame = 0; frame < 30; ++frame) EXPECT_OK(sph_world_step(w.world, 1.0f / 60.0f));
  expect_all_finite(&w);
  p = (float*)ext_copy(w.world, SPH_ATTRIBUTE_POSITION, &n);
  for (i = 0; i < n; ++i) {
    print_message("  huge SDF: particle at y %.5f m\n", p[3 * i + 1]);
    assert_true(p[3 * i + 1] >= -0.01f && p[3 * i + 1] <= 0.01f);
  }
  free(p);
  EXT_OK(sph_collider_destroy(w.world, id));
  EXT_OK(sph_sdf_destroy(sdf));
  ext_close(&w);
}

/* Spacings near float precision. Kernel coefficients go as 1 / h^9: at 1e-30 m or 1e30 m float
 * cannot hold them, and the world is refused, naming the spacing. 1e-4 m (h = 1.8e-4 m, the
 * coefficients near 1e33) works: a small block settles with finite state and density within 5 %
 * of rho0. A spacing near the float step of the positions (1e-6 m at 1 m, steps 6e-8 m) is
 * refused at spawn. */
static void test_spacing_near_float_precision(void** state) {
  static const float bad[] = {1e-30f, 1e-6f, 1e30f, FLT_MAX};
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def def;
  ext_world w;
  sph_fill_box_desc fill;
  sph_stats st;
  size_t k;
  uint32_t n = 0;
  int frame;
  (void)state;
  EXT_OK(sph_test_context_create(&context));
  for (k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
    sph_world_def_init(&def);
    def.particle_spacing = bad[k];
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "particle_spacing", sph_world_create(context, &def, &world));
    assert_null(world);
  }
  EXT_OK(sph_context_destroy(context));

  ext_open(&w, 512, 1e-4f);
  w.params.dt_min = 1e-8f;
  ext_set_params(&w);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 6e-4f;
  EXT_OK(sph_world_fill_box(w.world, &fill, &n));
  for (frame = 0; frame < 3; ++frame) assert_true(sph_world_step(w.world, 1e-3f) >= 0);
  expect_all_finite(&w);
  assert_int_equal(count_of(&w), n);
  sph_stats_init(&st);
  EXT_OK(sph_world_get_stats(w.world, &st));
  print_message("  spacing 1e-4 m: %u particles, density %.1f .. %.1f kg/m^3, %u substeps\n", n,
                st.density_min, st.density_max, st.substeps);
  assert_true(st.density_max <= 1050.0f);
  {
    const float far[3] = {10.0f, 0.0f, 0.0f}; /* 1e5 spacings out */
    sph_spawn_desc d;
    sph_spawn_desc_init(&d);
    d.count = 1;
    d.positions = far;
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "positions[0]", sph_world_spawn(w.world, &d, NULL));
  }
  ext_close(&w);
}

/* Capacity exhausted: a spawn or fill beyond the free capacity is CAPACITY and adds nothing; a
 * world filled to capacity steps; a source in a full world emits nothing and reports the
 * particles it could not emit as an SPH_EVENT_SOURCE_CAPACITY_REACHED event. */
static void test_capacity_exhausted(void** state) {
  ext_world w;
  sph_fill_box_desc fill;
  sph_spawn_desc d;
  float x[3 * 21];
  uint32_t n = 0, i, events = 0;
  sph_shape_desc shape;
  sph_sdf* region = NULL;
  sph_source_def source;
  sph_source_id source_id;
  sph_event event;
  capi_snapshot before;
  (void)state;
  ext_open(&w, 20, 0.02f);
  sph_fill_box_desc_init(&fill);
  fill.max.x = fill.max.y = fill.max.z = 0.2f;
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "capacity", sph_world_fill_box(w.world, &fill, &n));
  assert_int_equal(count_of(&w), 0);
  for (i = 0; i < 21; ++i) {
    x[3 * i] = 0.02f * (float)(i % 5);
    x[3 * i + 1] = 0.02f * (float)(i / 5);
    x[3 * i + 2] = 0.0f;
  }
  sph_spawn_desc_init(&d);
  d.positions = x;
  d.count = 21;
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "count", sph_world_spawn(w.world, &d, NULL));
  assert_int_equal(count_of(&w), 0);
  d.count = 20;
  EXPECT_OK(sph_world_spawn(w.world, &d, NULL));
  capi_snapshot_take(w.world, &before);
  d.count = 1;
  EXPECT_ERROR(SPH_ERROR_CAPACITY, "count", sph_world_spawn(w.world, &d, NULL));
  EXPECT_UNCHANGED(w.world, &before);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  EXT_OK(sph_sdf_create_shape(w.context, &shape, &region));
  sph_source_def_init(&source);
  source.region = region;
  source.transform.position.y = 1.0f;
  EXT_OK(sph_source_create(w.world, &source, &source_id));
  EXPECT_OK(sph_world_step(w.world, 0.01f));
  assert_int_equal(count_of(&w), 20);
  EXT_OK(sph_world_get_events(w.world, &event, 1, &events));
  assert_int_equal(events, 1);
  assert_int_equal(event.type, SPH_EVENT_SOURCE_CAPACITY_REACHED);
  assert_true(event.count > 0);
  expect_all_finite(&w);
  EXT_OK(sph_source_destroy(w.world, source_id));
  EXT_OK(sph_sdf_destroy(region));
  ext_close(&w);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_zero_particles),
      cmocka_unit_test(test_one_particle),
      cmocka_unit_test(test_two_particles),
      cmocka_unit_test(test_all_particles_at_one_point),
      cmocka_unit_test(test_far_from_origin_1e6),
      cmocka_unit_test(test_position_1e30_is_refused),
      cmocka_unit_test(test_step_carries_particle_beyond_reach),
      cmocka_unit_test(test_sdf_1x1x1),
      cmocka_unit_test(test_sdf_very_large),
      cmocka_unit_test(test_spacing_near_float_precision),
      cmocka_unit_test(test_capacity_exhausted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
