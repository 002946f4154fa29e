// SPDX-License-Identifier: MIT
/* Force fields (issue 4, item 5) on single particles in zero gravity, where the motion is
 * known in closed form: uniform, radial (push and pull, with falloff), vortex, a user grid,
 * a region that limits a field, and a rotated field frame. */
#include <math.h>

#include "scene_test.h"

static sph_force_field_def field_def(sph_force_field_kind kind) {
  sph_force_field_def d;
  sph_force_field_def_init(&d);
  d.kind = kind;
  return d;
}

static sph_force_field_id add_field(scene* s, const sph_force_field_def* d) {
  sph_force_field_id id;
  SCENE_OK(sph_force_field_create(s->world, d, &id));
  return id;
}

/* Velocity after `seconds` of a particle starting at (x, y, z) at rest. */
static void velocity_after(scene* s, float x, float y, float z, float seconds, float v[3], float p[3]) {
  const uint32_t id = scene_spawn_one(s, x, y, z, 0.0f, 0.0f, 0.0f);
  SCENE_OK(sph_world_step(s->world, seconds));
  scene_particle(s, id, p, v);
}

/* x = a t^2 / 2 and v = a t; symplectic Euler at dt = 1 ms over 0.5 s is off by dt / t =
 * 0.2 % in position and exact in velocity, so 1 % bounds both. */
static void test_uniform_field_accelerates_uniformly(void** state) {
  scene s;
  sph_force_field_def d = field_def(SPH_FORCE_FIELD_UNIFORM);
  float v[3], p[3];
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  d.vector.x = 1.0f;
  d.vector.y = 2.0f;
  add_field(&s, &d);
  velocity_after(&s, 0.0f, 0.0f, 0.0f, 0.5f, v, p);
  assert_true(fabsf(v[0] - 0.5f) < 0.005f && fabsf(v[1] - 1.0f) < 0.01f && fabsf(v[2]) < 1e-6f);
  assert_true(fabsf(p[0] - 0.125f) < 0.00125f && fabsf(p[1] - 0.25f) < 0.0025f);
  scene_close(&s);
}

/* A particle 10 cm from the centre of a radial field of strength 2 m/s^2: over 10 ms it moves
 * 0.1 mm, so the field is constant to 0.1 % and v = 0.02 m/s outward (inward when negative);
 * with a falloff radius of 20 cm the field is halved. */
static void test_radial_field_pushes_pulls_and_fades(void** state) {
  const float strengths[2] = {2.0f, -2.0f};
  int k;
  (void)state;
  for (k = 0; k < 3; ++k) {
    scene s;
    sph_force_field_def d = field_def(SPH_FORCE_FIELD_RADIAL);
    float v[3], p[3], expected;
    scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
    d.strength = strengths[k % 2];
    d.falloff_radius = k == 2 ? 0.2f : 0.0f;
    add_field(&s, &d);
    velocity_after(&s, 0.1f, 0.0f, 0.0f, 0.01f, v, p);
    expected = d.strength * 0.01f * (k == 2 ? 0.5f : 1.0f);
    assert_true(fabsf(v[0] - expected) <= 0.01f * fabsf(expected));
    assert_true(fabsf(v[1]) < 1e-7f && fabsf(v[2]) < 1e-7f);
    scene_close(&s);
  }
}

/* A vortex about +y: at (0.1, 0, 0) the push is y x x = -z; over 10 ms the particle's
 * velocity is -0.01 m/s in z and (to first order) nothing radially. */
static void test_vortex_field_turns_around_axis(void** state) {
  scene s;
  sph_force_field_def d = field_def(SPH_FORCE_FIELD_VORTEX);
  float v[3], p[3];
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  d.vector.y = 3.0f; /* normalised by the library */
  d.strength = 1.0f;
  add_field(&s, &d);
  velocity_after(&s, 0.1f, 0.0f, 0.0f, 0.01f, v, p);
  assert_true(fabsf(v[2] + 0.01f) < 1e-4f);
  assert_true(fabsf(v[0]) < 1e-4f && fabsf(v[1]) < 1e-7f);
  scene_close(&s);
}

/* A field with a region acts inside it only; a grid field applies its samples; a rotated
 * field frame rotates its acceleration. */
static void test_region_grid_and_frame(void** state) {
  scene s;
  sph_shape_desc shape;
  sph_sdf* ball;
  sph_force_field_def d = field_def(SPH_FORCE_FIELD_UNIFORM);
  sph_grid_desc grid;
  float samples[8 * 3];
  float v[3], p[3];
  int i;
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  ball = scene_shape(&s, &shape);
  d.vector.x = 1.0f;
  d.region = ball;
  add_field(&s, &d);
  velocity_after(&s, 0.2f, 0.0f, 0.0f, 0.01f, v, p); /* outside the region */
  assert_true(fabsf(v[0]) < 1e-7f);
  velocity_after(&s, 0.0f, 0.0f, 0.0f, 0.01f, v, p); /* inside it */
  assert_true(fabsf(v[0] - 0.01f) < 1e-5f);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);

  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  d = field_def(SPH_FORCE_FIELD_GRID);
  sph_grid_desc_init(&grid);
  grid.dims[0] = grid.dims[1] = grid.dims[2] = 2;
  grid.components = 3;
  for (i = 0; i < 8; ++i) {
    samples[3 * i] = 0.0f;
    samples[3 * i + 1] = 3.0f;
    samples[3 * i + 2] = 0.0f;
  }
  grid.data = samples;
  d.grid = &grid;
  add_field(&s, &d);
  velocity_after(&s, 0.5f, 0.5f, 0.5f, 0.01f, v, p);
  assert_true(fabsf(v[1] - 0.03f) < 3e-5f && fabsf(v[0]) < 1e-7f);
  scene_close(&s);

  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  d = field_def(SPH_FORCE_FIELD_UNIFORM);
  d.vector.x = 1.0f;
  d.transform.rotation.z = sinf(0.25f * 3.14159265f); /* 90 degrees about z: x -> y */
  d.transform.rotation.w = cosf(0.25f * 3.14159265f);
  add_field(&s, &d);
  velocity_after(&s, 0.0f, 0.0f, 0.0f, 0.01f, v, p);
  assert_true(fabsf(v[1] - 0.01f) < 1e-5f && fabsf(v[0]) < 1e-6f);
  scene_close(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uniform_field_accelerates_uniformly),
      cmocka_unit_test(test_radial_field_pushes_pulls_and_fades),
      cmocka_unit_test(test_vortex_field_turns_around_axis),
      cmocka_unit_test(test_region_grid_and_frame),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
