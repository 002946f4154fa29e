#include "validation_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int validation_full(void) {
  const char* v = getenv("SPH_VALIDATION_FULL");
  return v != NULL && strcmp(v, "1") == 0;
}

const char* validation_output_dir(void) {
  const char* v = getenv("SPH_VALIDATION_OUT");
  return (v != NULL && v[0] != '\0') ? v : NULL;
}

FILE* validation_open_output(const char* name) {
  char path[4096];
  const char* dir = validation_output_dir();
  if (dir == NULL) return NULL;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return fopen(path, "w");
}

uint32_t validation_lattice_box(const uint32_t n[3], double step, const double origin[3], float** positions) {
  const uint64_t cells = (uint64_t)n[0] * n[1] * n[2];
  float* p = (float*)malloc(sizeof(float) * 3 * (cells + 1));
  uint32_t count = 0;
  assert_non_null(p);
  for (uint32_t k = 0; k < n[2]; ++k)
    for (uint32_t j = 0; j < n[1]; ++j)
      for (uint32_t i = 0; i < n[0]; ++i) {
        if ((i + j + k) % 2) continue;
        p[3 * count] = (float)(origin[0] + (i + 0.5) * step);
        p[3 * count + 1] = (float)(origin[1] + (j + 0.5) * step);
        p[3 * count + 2] = (float)(origin[2] + (k + 0.5) * step);
        ++count;
      }
  *positions = p;
  return count;
}

sph_collider_id validation_tank(sph_context* context, sph_world* world, const double min[3],
                                const double max[3], double voxel, float friction, sph_sdf** out_sdf) {
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id id = {0};
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = (float)(0.5 * (max[0] - min[0]));
  shape.half_extents.y = (float)(0.5 * (max[1] - min[1]));
  shape.half_extents.z = (float)(0.5 * (max[2] - min[2]));
  shape.voxel_size = (float)voxel;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &sdf));
  sph_collider_def_init(&def);
  def.flags = SPH_COLLIDER_FLAG_INVERTED;
  def.sdf = sdf;
  def.transform = sph_transform_identity();
  def.transform.position.x = (float)(0.5 * (max[0] + min[0]));
  def.transform.position.y = (float)(0.5 * (max[1] + min[1]));
  def.transform.position.z = (float)(0.5 * (max[2] + min[2]));
  def.friction = friction;
  EXPECT_OK(sph_collider_create(world, &def, &id));
  *out_sdf = sdf;
  return id;
}

double validation_kinetic_energy(const sph_world* world, float mass) {
  float* v = NULL;
  double e = 0.0;
  const uint32_t n = physics_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v);
  for (uint32_t i = 0; i < 3 * n; ++i) e += 0.5 * mass * (double)v[i] * v[i];
  free(v);
  return e;
}
