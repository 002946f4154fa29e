// SPDX-License-Identifier: MIT
/* Thesis figure 7 through the C API alone (the scene of samples/scenes/fig7_drop_into_tank.json):
 * a big sphere of liquid falls into an open tank, a hollow box collider; 2.5 s later, with the
 * pool near rest, a second sphere is added above it and falls in. About 58,000 particles at
 * 1 cm. Every frame's particles are written as CSV.
 *
 * Usage: fig7_drop_into_tank [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/fig7_drop_into_tank_c, 300 frames at 60 fps) */
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
  const char* out_dir = "out/fig7_drop_into_tank_c";
  int frames = 300, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc tank_shape;
  sph_collider_def tank;
  sph_collider_id tank_id;
  sph_sink_def bounds;
  sph_sink_id bounds_id;
  sph_fill_sphere_desc drop;
  sph_sdf* tank_sdf = NULL;
  int second_added = 0;
  status = sample_parse_args(argc, argv, "fig7_drop_into_tank", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def); /* water at 1 cm */
  world_def.capacity = 64000;
  world_def.particle_spacing = 0.01f;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params);
  params.dt_max = 0.0005f; /* a 1 m/s splash at 1 cm spacing wants shorter steps than the default */
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  /* The tank: a hollow box, inside 60 cm x 70 cm x 60 cm with 2 cm walls, open at the top. */
  sph_shape_desc_init(&tank_shape);
  tank_shape.shape = SPH_SHAPE_BOX;
  tank_shape.half_extents.x = 0.3f;
  tank_shape.half_extents.y = 0.35f;
  tank_shape.half_extents.z = 0.3f;
  tank_shape.wall_thickness = 0.02f;
  tank_shape.flags = SPH_SHAPE_FLAG_OPEN_TOP;
  tank_shape.voxel_size = 0.005f;
  if (sample_failed(sph_sdf_create_shape(context, &tank_shape, &tank_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&tank);
  tank.sdf = tank_sdf;
  tank.transform = sph_transform_identity();
  tank.transform.position.y = 0.35f; /* the floor at y = 0 */
  tank.friction = 0.1f;
  if (sample_failed(sph_collider_create(world, &tank, &tank_id), "sph_collider_create")) goto done;

  /* Whatever splashes out of the tank and falls away is removed. */
  sph_sink_def_init(&bounds);
  bounds.mode = SPH_SINK_OUTSIDE_BOUNDS;
  bounds.bounds_min.x = -1.0f;
  bounds.bounds_min.y = -0.5f;
  bounds.bounds_min.z = -1.0f;
  bounds.bounds_max.x = 1.0f;
  bounds.bounds_max.y = 2.0f;
  bounds.bounds_max.z = 1.0f;
  if (sample_failed(sph_sink_create(world, &bounds, &bounds_id), "sph_sink_create")) goto done;

  /* The first sphere, 34 cm across, its bottom 25 cm above the floor. */
  sph_fill_sphere_desc_init(&drop);
  drop.center.y = 0.42f;
  drop.radius = 0.17f;
  if (sample_failed(sph_world_fill_sphere(world, &drop, NULL), "sph_world_fill_sphere")) goto done;

  printf("fig7_drop_into_tank: %d frames -> %s/\n", frames, out_dir);
  if (sample_write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    const double t = (frame - 1) / 60.0;    /* the time at the frame's start */
    if (!second_added && t >= 2.5 - 1e-6) { /* the second sphere */
      drop.center.x = 0.05f;
      drop.center.y = 0.62f;
      drop.center.z = -0.04f;
      if (sample_failed(sph_world_fill_sphere(world, &drop, NULL), "sph_world_fill_sphere")) goto done;
      second_added = 1;
    }
    if (sample_step_and_write(world, out_dir, frame, frames)) goto done;
  }
  status = 0;

done:
  sph_sdf_destroy(tank_sdf);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
