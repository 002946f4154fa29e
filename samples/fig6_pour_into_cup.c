// SPDX-License-Identifier: MIT
/* Thesis figure 6 through the C API alone (the scene of samples/scenes/fig6_pour_into_cup.json):
 * a continuous source pours liquid into a cup standing on a ground plane for 2.5 s; then the cup
 * tips over about its bottom edge and pours the liquid out onto the ground. The cup is a
 * kinematic collider: every frame it is given the pose it must reach by the frame's end
 * (sph_collider_set_target_transform), here a rotation about a pivot on its bottom edge. About
 * 270,000 particles at 5 mm: a big-machine scene. Every frame is written as CSV.
 *
 * Usage: fig6_pour_into_cup [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/fig6_pour_into_cup_c, 360 frames at 60 fps) */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sample_io.h"
#include "sph_c.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/fig6_pour_into_cup_c";
  int frames = 360, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id ground_id, cup_id;
  sph_source_def spout;
  sph_source_id spout_id;
  sph_sink_def bounds;
  sph_sink_id bounds_id;
  sph_sdf *ground_sdf = NULL, *cup_sdf = NULL, *spout_sdf = NULL;
  int pouring = 1;
  const double pi = 3.14159265358979;
  status = sample_parse_args(argc, argv, "fig6_pour_into_cup", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def);
  world_def.capacity = 320000;
  world_def.particle_spacing = 0.005f;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params);
  params.dt_max = 0.0003f; /* sqrt(k) dt below 0.4 h at h = 9 mm */
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  /* The ground: solid below y = 0 over 2.4 m x 2.4 m. */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_PLANE;
  shape.half_extents.x = 1.2f;
  shape.half_extents.y = 0.05f;
  shape.half_extents.z = 1.2f;
  shape.voxel_size = 0.01f;
  if (sample_failed(sph_sdf_create_shape(context, &shape, &ground_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&def);
  def.sdf = ground_sdf;
  def.transform = sph_transform_identity();
  def.friction = 0.2f;
  if (sample_failed(sph_collider_create(world, &def, &ground_id), "sph_collider_create")) goto done;

  /* The cup: inner radius 16 cm, 40 cm tall, 1.5 cm walls and floor, standing on the ground. */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_CUP;
  shape.radius = 0.16f;
  shape.half_height = 0.2f;
  shape.wall_thickness = 0.015f;
  shape.voxel_size = 0.0025f;
  if (sample_failed(sph_sdf_create_shape(context, &shape, &cup_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&def);
  def.sdf = cup_sdf;
  def.transform = sph_transform_identity();
  def.transform.position.y = 0.2f;
  def.friction = 0.1f;
  if (sample_failed(sph_collider_create(world, &def, &cup_id), "sph_collider_create")) goto done;

  /* The spout: a disc 9 cm across, 20 cm above the rim, refilled every step as the stream
   * leaves it (at 1.5 m/s the liquid falls 2.5 cm a frame, less than the disc's 3 cm, so the
   * stream has no gaps), at most 120,000 particles a second. */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_CYLINDER;
  shape.radius = 0.045f;
  shape.half_height = 0.015f;
  shape.voxel_size = 0.0025f;
  if (sample_failed(sph_sdf_create_shape(context, &shape, &spout_sdf), "sph_sdf_create_shape")) goto done;
  sph_source_def_init(&spout);
  spout.mode = SPH_SOURCE_CONTINUOUS;
  spout.region = spout_sdf;
  spout.transform = sph_transform_identity();
  spout.transform.position.x = 0.02f;
  spout.transform.position.y = 0.6f;
  spout.velocity.y = -1.5f;
  spout.rate = 120000.0f;
  if (sample_failed(sph_source_create(world, &spout, &spout_id), "sph_source_create")) goto done;

  /* Whatever leaves the ground's extent is removed. */
  sph_sink_def_init(&bounds);
  bounds.mode = SPH_SINK_OUTSIDE_BOUNDS;
  bounds.bounds_min.x = -1.2f;
  bounds.bounds_min.y = -0.2f;
  bounds.bounds_min.z = -1.2f;
  bounds.bounds_max.x = 1.2f;
  bounds.bounds_max.y = 1.5f;
  bounds.bounds_max.z = 1.2f;
  if (sample_failed(sph_sink_create(world, &bounds, &bounds_id), "sph_sink_create")) goto done;

  printf("fig6_pour_into_cup: %d frames -> %s/\n", frames, out_dir);
  if (sample_write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    const double t = (frame - 1) / 60.0; /* the time at the frame's start */
    if (pouring && t >= 2.5 - 1e-6) {    /* the pour stops after 2.5 s */
      if (sample_failed(sph_source_destroy(world, spout_id), "sph_source_destroy")) goto done;
      pouring = 0;
    }
    { /* from 2.8 s to 4.3 s the cup tips 95 degrees about its bottom edge (x = 0.175, y = 0) */
      const double end = t + 1.0 / 60.0, s = (end - 2.8) / 1.5;
      const double angle = 95.0 * pi / 180.0 * (s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s);
      sph_transform target = sph_transform_identity();
      /* the centre, (0, 0.2) at rest, turned by -angle about the pivot */
      target.position.x = (float)(0.175 - 0.175 * cos(angle) + 0.2 * sin(angle));
      target.position.y = (float)(0.175 * sin(angle) + 0.2 * cos(angle));
      target.rotation.z = (float)sin(-0.5 * angle);
      target.rotation.w = (float)cos(-0.5 * angle);
      if (sample_failed(sph_collider_set_target_transform(world, cup_id, &target),
                        "sph_collider_set_target_transform"))
        goto done;
    }
    if (sample_step_and_write(world, out_dir, frame, frames)) goto done;
  }
  status = 0;

done:
  sph_sdf_destroy(ground_sdf);
  sph_sdf_destroy(cup_sdf);
  sph_sdf_destroy(spout_sdf);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
