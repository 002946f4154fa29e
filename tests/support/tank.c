// SPDX-License-Identifier: MIT
/* The closed tank (an inverted box collider) and the dam break: a column of water in it. */
#include "support.h"

sph_result support_tank_create(sph_context* context, sph_world* world, const support_tank* tank,
                               sph_sdf** sdf, sph_collider_id* collider) {
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id id;
  sph_sdf* asset = NULL;
  sph_result r;
  if (sdf) *sdf = NULL;
  if ((r = sph_shape_desc_init(&shape)) != SPH_OK) return r;
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents = tank->half_extents;
  shape.voxel_size = tank->voxel_size;
  if ((r = sph_sdf_create_shape(context, &shape, &asset)) != SPH_OK) return r;
  if (sdf) *sdf = asset;
  if ((r = sph_collider_def_init(&def)) != SPH_OK) return r;
  def.sdf = asset;
  def.flags = SPH_COLLIDER_FLAG_INVERTED;
  def.transform = sph_transform_identity();
  def.transform.position = tank->centre;
  def.friction = tank->friction;
  if ((r = sph_collider_create(world, &def, &id)) != SPH_OK) return r;
  if (collider) *collider = id;
  return sdf ? SPH_OK : sph_sdf_destroy(asset);
}

sph_result support_tank_between(sph_context* context, sph_world* world, const double min[3],
                                const double max[3], double voxel_size, float friction, sph_sdf** sdf,
                                sph_collider_id* collider) {
  support_tank tank;
  tank.centre.x = (float)(0.5 * (max[0] + min[0]));
  tank.centre.y = (float)(0.5 * (max[1] + min[1]));
  tank.centre.z = (float)(0.5 * (max[2] + min[2]));
  tank.half_extents.x = (float)(0.5 * (max[0] - min[0]));
  tank.half_extents.y = (float)(0.5 * (max[1] - min[1]));
  tank.half_extents.z = (float)(0.5 * (max[2] - min[2]));
  tank.voxel_size = (float)voxel_size;
  tank.friction = friction;
  return support_tank_create(context, world, &tank, sdf, collider);
}

sph_result support_dam_break(sph_context* context, sph_world* world, const support_tank* tank,
                             sph_vec3 column_min, sph_vec3 column_max, sph_sdf** sdf,
                             sph_collider_id* collider, uint32_t* count) {
  sph_fill_box_desc column;
  sph_result r;
  if ((r = support_tank_create(context, world, tank, sdf, collider)) != SPH_OK) return r;
  if ((r = sph_fill_box_desc_init(&column)) != SPH_OK) return r;
  column.min = column_min;
  column.max = column_max;
  return sph_world_fill_box(world, &column, count);
}
