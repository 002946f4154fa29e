// SPDX-License-Identifier: MIT
/* A wave tank through the C API alone (the scene of samples/scenes/wave_tank.json): a paddle
 * at one end of a long tank swings back and forth and sends waves down it. The paddle is a
 * kinematic collider: every frame it gets the pose it must reach by the frame's end
 * (sph_collider_set_target_transform), and the library moves it smoothly through the substeps,
 * pushing the water with the velocity that motion implies. Here the motion is a sine; the
 * scene file gives the same swing as looping keyframes. Every frame is written as CSV.
 *
 * Usage: wave_tank [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/wave_tank_c, 300 frames at 60 fps) */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sample_io.h"
#include "sph_c.h"
#include "support.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/wave_tank_c";
  int frames = 300, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id paddle_id;
  /* The tank: an inverted box, inside 2 m x 0.6 m x 0.3 m, floor at y = 0 (support_tank_create,
   * tests/support/tank.c: a box SDF placed with SPH_COLLIDER_FLAG_INVERTED). */
  const support_tank tank = {{0.0f, 0.3f, 0.0f}, {1.0f, 0.3f, 0.15f}, 0.01f, 0.0f};
  sph_fill_box_desc water;
  sph_sdf *tank_sdf = NULL, *paddle_sdf = NULL;
  const double period = 1.0; /* s */
  status = sample_parse_args(argc, argv, "wave_tank", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def);
  world_def.capacity = 24000;
  world_def.particle_spacing = 0.02f;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params);
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  if (sample_failed(support_tank_create(context, world, &tank, &tank_sdf, NULL), "support_tank_create"))
    goto done;

  /* The paddle: a 3 cm board across the tank near its left wall. */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = 0.015f;
  shape.half_extents.y = 0.28f;
  shape.half_extents.z = 0.16f;
  shape.voxel_size = 0.005f;
  if (sample_failed(sph_sdf_create_shape(context, &shape, &paddle_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&def);
  def.sdf = paddle_sdf;
  def.transform = sph_transform_identity();
  def.transform.position.x = -0.93f;
  def.transform.position.y = 0.27f;
  if (sample_failed(sph_collider_create(world, &def, &paddle_id), "sph_collider_create")) goto done;

  /* Still water 20 cm deep to the right of the paddle. */
  sph_fill_box_desc_init(&water);
  water.min.x = -0.9f;
  water.min.y = 0.0f;
  water.min.z = -0.15f;
  water.max.x = 1.0f;
  water.max.y = 0.2f;
  water.max.z = 0.15f;
  if (sample_failed(sph_world_fill_box(world, &water, NULL), "sph_world_fill_box")) goto done;

  printf("wave_tank: %d frames -> %s/\n", frames, out_dir);
  if (sample_write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    const double t = (frame - 1) / 60.0; /* the time at the frame's start */
    { /* the paddle's pose at the frame's end: 16 cm forward and 15 degrees over at the peak */
      const double end = t + 1.0 / 60.0;
      const double s = 0.5 * (1.0 - cos(2.0 * 3.14159265358979 * end / period));
      const double half_angle = 0.5 * (-15.0 * 3.14159265358979 / 180.0) * s;
      sph_transform target = sph_transform_identity();
      target.position.x = (float)(-0.93 + 0.16 * s);
      target.position.y = 0.27f;
      target.rotation.z = (float)sin(half_angle); /* about the z axis */
      target.rotation.w = (float)cos(half_angle);
      if (sample_failed(sph_collider_set_target_transform(world, paddle_id, &target),
                        "sph_collider_set_target_transform"))
        goto done;
    }
    if (sample_step_and_write(world, out_dir, frame, frames)) goto done;
  }
  status = 0;

done:
  sph_sdf_destroy(tank_sdf);
  sph_sdf_destroy(paddle_sdf);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
