#include "physics_util.h"

#include <stdlib.h>
#include <string.h>

void physics_create(const sph_world_def* def, sph_context** context, sph_world** world) {
  EXPECT_OK(sph_test_context_create(context));
  EXPECT_OK(sph_world_create(*context, def, world));
}

void physics_destroy(sph_context* context, sph_world* world) {
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

uint32_t physics_copy_by_id(const sph_world* world, sph_attribute attribute, void** out) {
  const size_t width = (attribute == SPH_ATTRIBUTE_POSITION || attribute == SPH_ATTRIBUTE_VELOCITY) ? 12 : 4;
  uint32_t n = 0;
  uint32_t* ids;
  unsigned char* raw;
  unsigned char* sorted;
  EXPECT_OK(sph_world_get_particle_count(world, &n));
  ids = (uint32_t*)malloc(sizeof(uint32_t) * (n + 1));
  raw = (unsigned char*)malloc(width * (n + 1));
  sorted = (unsigned char*)calloc(n + 1, width);
  assert_non_null(ids);
  assert_non_null(raw);
  assert_non_null(sorted);
  EXPECT_OK(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, ids, sizeof(uint32_t) * n, 0, 0, n, NULL));
  EXPECT_OK(sph_world_copy_attribute(world, attribute, raw, width * n, 0, 0, n, NULL));
  /* The tests spawn once into an empty world, so ids are 0 .. n-1. */
  for (uint32_t i = 0; i < n; ++i) {
    assert_true(ids[i] < n);
    memcpy(sorted + width * ids[i], raw + width * i, width);
  }
  free(ids);
  free(raw);
  *out = sorted;
  return n;
}

uint32_t physics_fcc_sphere(float spacing, float radius, float** positions) {
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def def;
  sph_fill_sphere_desc sphere;
  uint32_t n = 0;
  sph_world_def_init(&def);
  def.particle_spacing = spacing;
  physics_create(&def, &context, &world);
  sph_fill_sphere_desc_init(&sphere);
  sphere.radius = radius;
  EXPECT_OK(sph_world_fill_sphere(world, &sphere, &n));
  assert_int_equal(physics_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)positions), n);
  physics_destroy(context, world);
  return n;
}

void physics_set_params(sph_world* world, float gx, float gy, float gz, float dt_min, float dt_max) {
  sph_world_params p;
  sph_world_params_init(&p);
  p.gravity.x = gx;
  p.gravity.y = gy;
  p.gravity.z = gz;
  p.dt_min = dt_min;
  p.dt_max = dt_max;
  EXPECT_OK(sph_world_set_params(world, &p));
}

double physics_spawn_disturbed(sph_world* world, const float* positions, uint32_t n, double disturbance,
                               uint64_t* rng) {
  sph_spawn_desc spawn;
  float mass = 0.0f;
  double ke = 0.0;
  float* velocities = (float*)malloc(sizeof(float) * 3 * (n > 0 ? n : 1));
  assert_non_null(velocities);
  for (uint32_t i = 0; i < 3 * n; ++i)
    velocities[i] = (float)(disturbance * (2.0 * sph_test_random(rng) - 1.0));
  sph_spawn_desc_init(&spawn);
  spawn.count = n;
  spawn.positions = positions;
  spawn.velocities = velocities;
  EXPECT_OK(sph_world_spawn(world, &spawn, NULL));
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  for (uint32_t i = 0; i < 3 * n; ++i) ke += 0.5 * mass * (double)velocities[i] * velocities[i];
  free(velocities);
  return ke;
}
