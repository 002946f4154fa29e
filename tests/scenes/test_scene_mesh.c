// SPDX-License-Identifier: MIT
/* SDF assets from triangle meshes (issue 21, item 4): a meshed sphere and box against their
 * analytic distances within half a voxel, a sphere with a hole still signed inside, bad input
 * refused with the field named, and a small dam break around a mesh obstacle. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

static const float kG = 9.81f;

/* A triangle soup (three vertices per triangle, indices 0..n-1). */
typedef struct soup {
  float* vertices;
  uint32_t* indices;
  uint32_t triangles, capacity;
} soup;

static void soup_add(soup* m, const float a[3], const float b[3], const float c[3]) {
  uint32_t k;
  if (m->triangles == m->capacity) {
    m->capacity = m->capacity ? 2 * m->capacity : 64;
    m->vertices = realloc(m->vertices, 36 * (size_t)m->capacity);
    m->indices = realloc(m->indices, 12 * (size_t)m->capacity);
    assert_non_null(m->vertices);
    assert_non_null(m->indices);
  }
  for (k = 0; k < 3; ++k) {
    m->vertices[9 * m->triangles + k] = a[k];
    m->vertices[9 * m->triangles + 3 + k] = b[k];
    m->vertices[9 * m->triangles + 6 + k] = c[k];
  }
  for (k = 0; k < 3; ++k) m->indices[3 * m->triangles + k] = 3 * m->triangles + k;
  ++m->triangles;
}

static void soup_free(soup* m) {
  free(m->vertices);
  free(m->indices);
  memset(m, 0, sizeof *m);
}

static void normalize_to(float v[3], float radius) {
  const float n = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  v[0] *= radius / n;
  v[1] *= radius / n;
  v[2] *= radius / n;
}

/* Adds the triangle, wound counter-clockwise seen from outside a convex shape around `centre`. */
static void add_outward(soup* m, const float a[3], const float b[3], const float c[3],
                        const float centre[3]) {
  const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const float n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const float out = n[0] * (a[0] - centre[0]) + n[1] * (a[1] - centre[1]) + n[2] * (a[2] - centre[2]);
  if (out >= 0.0f)
    soup_add(m, a, b, c);
  else
    soup_add(m, a, c, b);
}

/* An icosphere of `radius`: the icosahedron split `levels` times, corners pushed to the sphere.
 * Triangles whose centroid lies within `hole_degrees` of +y are left out (0: closed). */
static void subdivide(soup* m, const float a[3], const float b[3], const float c[3], float radius, int levels,
                      float hole_cos) {
  static const float origin[3] = {0.0f, 0.0f, 0.0f};
  if (levels == 0) {
    float g[3] = {a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]};
    normalize_to(g, 1.0f);
    if (g[1] <= hole_cos) add_outward(m, a, b, c, origin);
    return;
  } else {
    float ab[3], bc[3], ca[3];
    int k;
    for (k = 0; k < 3; ++k) {
      ab[k] = 0.5f * (a[k] + b[k]);
      bc[k] = 0.5f * (b[k] + c[k]);
      ca[k] = 0.5f * (c[k] + a[k]);
    }
    normalize_to(ab, radius);
    normalize_to(bc, radius);
    normalize_to(ca, radius);
    subdivide(m, a, ab, ca, radius, levels - 1, hole_cos);
    subdivide(m, ab, b, bc, radius, levels - 1, hole_cos);
    subdivide(m, ca, bc, c, radius, levels - 1, hole_cos);
    subdivide(m, ab, bc, ca, radius, levels - 1, hole_cos);
  }
}

static soup icosphere(float radius, int levels, float hole_degrees) {
  static const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  const float t = 0.5f * (1.0f + sqrtf(5.0f));
  float corners[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  soup m;
  int f;
  memset(&m, 0, sizeof m);
  for (f = 0; f < 12; ++f) normalize_to(corners[f], radius);
  for (f = 0; f < 20; ++f)
    subdivide(&m, corners[faces[f][0]], corners[faces[f][1]], corners[faces[f][2]], radius, levels,
              cosf(hole_degrees * 3.14159265f / 180.0f));
  return m;
}

/* A box of half extents h around `centre`: 12 triangles, outward. */
static soup box_mesh(const float centre[3], const float h[3]) {
  static const int quads[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  float corner[8][3];
  soup m;
  int c, q;
  memset(&m, 0, sizeof m);
  for (c = 0; c < 8; ++c) {
    corner[c][0] = centre[0] + ((c & 1) ? h[0] : -h[0]);
    corner[c][1] = centre[1] + ((c & 2) ? h[1] : -h[1]);
    corner[c][2] = centre[2] + ((c & 4) ? h[2] : -h[2]);
  }
  for (q = 0; q < 6; ++q) {
    add_outward(&m, corner[quads[q][0]], corner[quads[q][1]], corner[quads[q][2]], centre);
    add_outward(&m, corner[quads[q][0]], corner[quads[q][2]], corner[quads[q][3]], centre);
  }
  return m;
}

static sph_result mesh_sdf(sph_context* context, const soup* m, float voxel, sph_sdf** out) {
  sph_mesh_desc d;
  sph_mesh_desc_init(&d);
  d.vertices = m->vertices;
  d.vertex_count = 3 * m->triangles;
  d.indices = m->indices;
  d.index_count = 3 * m->triangles;
  d.voxel_size = voxel;
  return sph_sdf_create_from_mesh(context, &d, out);
}

static float box_distance(const float p[3], const float centre[3], const float h[3]) {
  float q[3], outside = 0.0f, inside = -1e30f;
  int a;
  for (a = 0; a < 3; ++a) {
    q[a] = fabsf(p[a] - centre[a]) - h[a];
    outside += q[a] > 0.0f ? q[a] * q[a] : 0.0f;
    inside = fmaxf(inside, q[a]);
  }
  return sqrtf(outside) + fminf(inside, 0.0f);
}

/* The worst |sampled - analytic| over every voxel centre of the asset, whose voxel (0, 0, 0)
 * sits at the mesh's bounds minimum less 4 voxels (sph_sdf_create_from_mesh's layout). */
static float worst_voxel_error(const sph_sdf* sdf, const float bounds_min[3], float voxel,
                               float (*exact)(const float p[3], const void* shape), const void* shape) {
  uint32_t dims[3], i, j, k;
  float worst = 0.0f;
  SCENE_OK(sph_sdf_get_dims(sdf, dims));
  for (k = 0; k < dims[2]; ++k)
    for (j = 0; j < dims[1]; ++j)
      for (i = 0; i < dims[0]; ++i) {
        const float p[3] = {bounds_min[0] + voxel * ((float)i - 4.0f),
                            bounds_min[1] + voxel * ((float)j - 4.0f),
                            bounds_min[2] + voxel * ((float)k - 4.0f)};
        const sph_vec3 local = {p[0], p[1], p[2]};
        float d = 0.0f;
        SCENE_OK(sph_sdf_sample(sdf, local, &d));
        worst = fmaxf(worst, fabsf(d - exact(p, shape)));
      }
  print_message("worst error over %u voxels: %.5f m (voxel %.3f m)\n", dims[0] * dims[1] * dims[2], worst,
                voxel);
  return worst;
}

static float sphere_exact(const float p[3], const void* radius) {
  return sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - *(const float*)radius;
}

static float box_exact(const float p[3], const void* half) {
  static const float centre[3] = {0.0f, 0.0f, 0.0f};
  return box_distance(p, centre, (const float*)half);
}

/* A sphere of radius 0.3 m as 1,280 triangles at 2 cm voxels: every voxel centre within half a
 * voxel (the bound) of |p| - r. The facets lie inside the sphere by at most
 * r (1 - cos 5.2 deg) = 1.2 mm, so the bound leaves 9 mm for the distance field's own error. */
static void test_meshed_sphere_matches_analytic(void** state) {
  const float radius = 0.3f, voxel = 0.02f;
  float bounds_min[3] = {1e30f, 1e30f, 1e30f};
  soup m = icosphere(radius, 3, 0.0f);
  scene s;
  sph_sdf* sdf = NULL;
  uint32_t v;
  int a;
  (void)state;
  assert_int_equal(m.triangles, 1280);
  for (v = 0; v < 3 * m.triangles; ++v)
    for (a = 0; a < 3; ++a) bounds_min[a] = fminf(bounds_min[a], m.vertices[3 * v + a]);
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  SCENE_OK(mesh_sdf(s.context, &m, voxel, &sdf));
  assert_true(worst_voxel_error(sdf, bounds_min, voxel, sphere_exact, &radius) < 0.5f * voxel);
  SCENE_OK(sph_sdf_destroy(sdf));
  scene_close(&s);
  soup_free(&m);
}

/* A box (0.2, 0.1, 0.15) m as 12 triangles: every voxel centre, inside (up to the box's medial
 * planes) and out (edge and corner regions), within half a voxel of the exact box distance;
 * packed and interleaved vertices alike. */
static void test_meshed_box_matches_analytic(void** state) {
  static const float centre[3] = {0.0f, 0.0f, 0.0f}, half[3] = {0.2f, 0.1f, 0.15f};
  const float voxel = 0.02f;
  const float bounds_min[3] = {-half[0], -half[1], -half[2]};
  soup m = box_mesh(centre, half);
  scene s;
  sph_sdf* sdf = NULL;
  (void)state;
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  SCENE_OK(mesh_sdf(s.context, &m, voxel, &sdf));
  assert_true(worst_voxel_error(sdf, bounds_min, voxel, box_exact, half) < 0.5f * voxel);
  SCENE_OK(sph_sdf_destroy(sdf));
  {
    /* The same box from an interleaved vertex buffer (position, then a normal and a uv: 8
     * floats, a 32-byte stride), as engines hold them: the same asset. */
    float* interleaved = calloc(8 * 3 * (size_t)m.triangles, sizeof(float));
    sph_mesh_desc d;
    uint32_t v;
    assert_non_null(interleaved);
    for (v = 0; v < 3 * m.triangles; ++v) {
      memcpy(&interleaved[8 * v], &m.vertices[3 * v], 3 * sizeof(float));
      interleaved[8 * v + 3] = NAN; /* never read */
    }
    sph_mesh_desc_init(&d);
    d.vertices = interleaved;
    d.vertex_stride = 8 * sizeof(float);
    d.vertex_count = 3 * m.triangles;
    d.indices = m.indices;
    d.index_count = 3 * m.triangles;
    d.voxel_size = voxel;
    SCENE_OK(sph_sdf_create_from_mesh(s.context, &d, &sdf));
    assert_true(worst_voxel_error(sdf, bounds_min, voxel, box_exact, half) < 0.5f * voxel);
    SCENE_OK(sph_sdf_destroy(sdf));
    free(interleaved);
  }
  scene_close(&s);
  soup_free(&m);
}

/* The same sphere missing a cap 8 degrees across its pole (a hole 8 cm wide, 4 voxels: below
 * the 6 of twice the default band) is still negative everywhere more than a voxel inside it
 * and positive everywhere more than a voxel outside, and so with its triangles flipped. */
static void test_sphere_with_hole_signs_inside(void** state) {
  const float radius = 0.3f, voxel = 0.02f;
  soup m = icosphere(radius, 3, 8.0f);
  scene s;
  int flipped;
  (void)state;
  assert_true(m.triangles < 1280 && m.triangles > 1250);
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  for (flipped = 0; flipped < 2; ++flipped) {
    sph_sdf* sdf = NULL;
    float x, y, z;
    uint32_t inside = 0, wrong = 0;
    SCENE_OK(mesh_sdf(s.context, &m, voxel, &sdf));
    for (z = -0.36f; z <= 0.36f; z += 0.03f)
      for (y = -0.36f; y <= 0.36f; y += 0.03f)
        for (x = -0.36f; x <= 0.36f; x += 0.03f) {
          const sph_vec3 p = {x, y, z};
          const float r = sqrtf(x * x + y * y + z * z);
          float d = 0.0f;
          SCENE_OK(sph_sdf_sample(sdf, p, &d));
          if (r < radius - voxel) {
            ++inside;
            wrong += d >= 0.0f;
          } else if (r > radius + voxel) {
            wrong += d <= 0.0f;
          }
        }
    assert_true(inside > 3000);
    assert_int_equal(wrong, 0);
    SCENE_OK(sph_sdf_destroy(sdf));
    {
      uint32_t t;
      for (t = 0; t < m.triangles; ++t) {
        const uint32_t swap = m.indices[3 * t + 1];
        m.indices[3 * t + 1] = m.indices[3 * t + 2];
        m.indices[3 * t + 2] = swap;
      }
    }
  }
  scene_close(&s);
  soup_free(&m);
}

static void expect_refused(sph_context* context, const sph_mesh_desc* d, sph_result expected,
                           const char* field) {
  sph_sdf* sdf = NULL;
  const sph_result r = sph_sdf_create_from_mesh(context, d, &sdf);
  if (r != expected) print_error("expected %d, got %d: %s\n", expected, r, sph_get_last_error());
  assert_int_equal(r, expected);
  assert_null(sdf);
  if (!strstr(sph_get_last_error(), field))
    print_error("'%s' does not name %s\n", sph_get_last_error(), field);
  assert_non_null(strstr(sph_get_last_error(), field));
}

/* Every bad input is refused with its own field named, and nothing is created. */
static void test_bad_meshes_are_refused(void** state) {
  float vertices[4 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  uint32_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  scene s;
  sph_mesh_desc good, d;
  sph_sdf* sdf = NULL;
  (void)state;
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  sph_mesh_desc_init(&good);
  good.vertices = vertices;
  good.vertex_count = 4;
  good.indices = indices;
  good.index_count = 12;
  good.voxel_size = 0.05f;
  SCENE_OK(sph_sdf_create_from_mesh(s.context, &good, &sdf));
  SCENE_OK(sph_sdf_destroy(sdf));
  assert_int_equal(sph_sdf_create_from_mesh(s.context, NULL, &sdf), SPH_ERROR_INVALID_ARGUMENT);
  assert_int_equal(sph_sdf_create_from_mesh(s.context, &good, NULL), SPH_ERROR_INVALID_ARGUMENT);
  d = good;
  d.vertices = NULL;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->vertices");
  d = good;
  d.indices = NULL;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->indices");
  d = good;
  d.index_count = 11;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->index_count");
  d = good;
  d.vertex_count = 2;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->vertex_count");
  d = good;
  d.vertex_count = 3; /* index 3 now points past the end */
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->indices[5]");
  d = good;
  d.vertex_stride = 8;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->vertex_stride");
  d = good;
  d.voxel_size = -0.1f;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->voxel_size");
  d = good;
  d.band_width = 0.5f;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->band_width");
  d = good;
  d.band_width = NAN;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->band_width");
  d = good;
  d.reserved0 = 1;
  expect_refused(s.context, &d, SPH_ERROR_INVALID_ARGUMENT, "desc->reserved0");
  d = good;
  d.voxel_size = 1e-4f; /* a 1 m mesh at 0.1 mm: 10^12 voxels */
  expect_refused(s.context, &d, SPH_ERROR_CAPACITY, "desc->voxel_size");
  vertices[4] = NAN;
  expect_refused(s.context, &good, SPH_ERROR_INVALID_ARGUMENT, "desc->vertices[1]");
  vertices[4] = 0.0f;
  vertices[7] = INFINITY;
  expect_refused(s.context, &good, SPH_ERROR_INVALID_ARGUMENT, "desc->vertices[2]");
  scene_close(&s);
}

/* A dam break around a mesh obstacle (a 12-triangle block standing 8 cm out of the tank floor,
 * narrower than the tank, so the water goes over and around it; its base is 2 cm below the
 * floor, so a particle that slid under it would count as 2 cm deep): over 40 frames no
 * particle goes deeper into the block than half a spacing (the tank test's bound), and the
 * water reaches past it. */
static void test_dam_break_around_mesh_obstacle(void** state) {
  const float spacing = 0.02f;
  const support_tank tank = {{0.0f, 0.2f, 0.0f}, {0.3f, 0.2f, 0.1f}, 0.01f, 0.0f};
  const sph_vec3 column_min = {-0.3f, 0.0f, -0.1f}, column_max = {-0.16f, 0.3f, 0.1f};
  static const float block_centre[3] = {0.06f, 0.03f, 0.0f}, block_half[3] = {0.03f, 0.05f, 0.05f};
  soup block = box_mesh(block_centre, block_half);
  scene s;
  sph_sdf *box = NULL, *obstacle = NULL;
  sph_collider_def def;
  sph_collider_id id;
  uint32_t n = 0, i, beyond = 0;
  float* x;
  float worst = -1.0f;
  int frame;
  (void)state;
  scene_open(&s, 4000, spacing, -kG, 1e-3f);
  SCENE_OK(support_dam_break(s.context, s.world, &tank, column_min, column_max, &box, NULL, &n));
  assert_true(n > 500);
  SCENE_OK(mesh_sdf(s.context, &block, 0.01f, &obstacle));
  sph_collider_def_init(&def);
  def.sdf = obstacle;
  SCENE_OK(sph_collider_create(s.world, &def, &id));
  x = malloc(12 * (size_t)n);
  assert_non_null(x);
  for (frame = 0; frame < 40; ++frame) {
    SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
    assert_int_equal(scene_positions(&s, x, n), n);
    for (i = 0; i < n; ++i) worst = fmaxf(worst, -box_distance(&x[3 * i], block_centre, block_half));
  }
  for (i = 0; i < n; ++i) beyond += x[3 * i] > block_centre[0] + block_half[0];
  print_message("deepest in the block %.5f m; %u of %u particles past it\n", worst, beyond, n);
  assert_true(worst < 0.5f * spacing);
  assert_true(beyond > n / 20);
  free(x);
  SCENE_OK(sph_sdf_destroy(obstacle));
  SCENE_OK(sph_sdf_destroy(box));
  scene_close(&s);
  soup_free(&block);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_meshed_sphere_matches_analytic),
      cmocka_unit_test(test_meshed_box_matches_analytic),
      cmocka_unit_test(test_sphere_with_hole_signs_inside),
      cmocka_unit_test(test_bad_meshes_are_refused),
      cmocka_unit_test(test_dam_break_around_mesh_obstacle),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
