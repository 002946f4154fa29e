// SPDX-License-Identifier: MIT
#include "scene_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void scene_ok(sph_result r, const char* call, const char* file, int line) {
  if (r < 0) {
    char message[2048];
    snprintf(message, sizeof message, "%s -> %s: %s", call, sph_result_string(r), sph_get_last_error());
    _fail(file, line);
    print_error("%s\n", message);
  }
}

void scene_open(scene* s, uint32_t capacity, float spacing, float gravity_y, float dt_max) {
  sph_world_def def;
  sph_world_params params;
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.particle_spacing = spacing;
  sph_world_params_init(&params);
  params.gravity.y = gravity_y;
  params.dt_max = dt_max;
  SCENE_OK(support_world_open(s, sph_test_backend(), &def, &params));
}

void scene_set_params(scene* s) { SCENE_OK(support_world_set_params(s)); }

void scene_close(scene* s) { SCENE_OK(support_world_close(s)); }

sph_sdf* scene_shape(scene* s, const sph_shape_desc* desc) {
  sph_sdf* sdf = NULL;
  SCENE_OK(sph_sdf_create_shape(s->context, desc, &sdf));
  return sdf;
}

sph_transform scene_at(float x, float y, float z) {
  sph_transform t = sph_transform_identity();
  t.position.x = x;
  t.position.y = y;
  t.position.z = z;
  return t;
}

static uint32_t copy_out(scene* s, sph_attribute a, void* dst, uint32_t max) {
  uint32_t n = 0;
  SCENE_OK(sph_world_get_particle_count(s->world, &n));
  assert_true(n <= max);
  SCENE_OK(support_read(s->world, a, dst, max, &n));
  return n;
}

uint32_t scene_positions(scene* s, float* p, uint32_t max) {
  return copy_out(s, SPH_ATTRIBUTE_POSITION, p, max);
}
uint32_t scene_velocities(scene* s, float* v, uint32_t max) {
  return copy_out(s, SPH_ATTRIBUTE_VELOCITY, v, max);
}
uint32_t scene_ids(scene* s, uint32_t* ids, uint32_t max) { return copy_out(s, SPH_ATTRIBUTE_ID, ids, max); }

uint32_t scene_spawn_one(scene* s, float x, float y, float z, float vx, float vy, float vz) {
  const float p[3] = {x, y, z}, v[3] = {vx, vy, vz};
  sph_spawn_desc d;
  uint32_t id = 0;
  sph_spawn_desc_init(&d);
  d.count = 1;
  d.positions = p;
  d.velocities = v;
  SCENE_OK(sph_world_spawn(s->world, &d, &id));
  return id;
}

void scene_particle(scene* s, uint32_t id, float position[3], float velocity[3]) {
  uint32_t n = 0, i;
  float *p, *v;
  uint32_t* ids;
  SCENE_OK(sph_world_get_particle_count(s->world, &n));
  p = malloc(12 * (size_t)n + 12);
  v = malloc(12 * (size_t)n + 12);
  ids = malloc(4 * (size_t)n + 4);
  assert_non_null(p);
  assert_non_null(v);
  assert_non_null(ids);
  scene_positions(s, p, n);
  scene_velocities(s, v, n);
  scene_ids(s, ids, n);
  for (i = 0; i < n; ++i)
    if (ids[i] == id) break;
  assert_true(i < n);
  memcpy(position, p + 3 * i, 12);
  memcpy(velocity, v + 3 * i, 12);
  free(p);
  free(v);
  free(ids);
}
