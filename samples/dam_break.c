/* The default demo scene, a dam break, built through the C API alone as an engine would
 * (the same scene as samples/scenes/dam_break.json, which sph-run plays): a column of water
 * collapses in a closed tank, an inverted box collider. Every frame's particles are written as
 * CSV (id, x, y, z, vx, vy, vz, density) to the output directory.
 *
 * Usage: dam_break [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/dam_break_c, 120 frames at 60 fps) */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sample_io.h"
#include "sph_c.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/dam_break_c";
  int frames = 120, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc tank_shape;
  sph_collider_def tank;
  sph_collider_id tank_id;
  sph_fill_box_desc column;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_sdf* tank_sdf = NULL;
  sph_stats stats;
  uint32_t count = 0;

  status = sample_parse_args(argc, argv, "dam_break", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def); /* water at 2 cm */
  world_def.capacity = 20000;
  world_def.particle_spacing = 0.02f;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params); /* gravity -9.81 y, k = 100, mu = 1, dt_max = 1 ms: the defaults */
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  /* The tank: a box SDF whose interior is 1 m x 0.6 m x 0.3 m, inverted so that the fluid stays
   * inside it. The floor is at y = 0. */
  sph_shape_desc_init(&tank_shape);
  tank_shape.shape = SPH_SHAPE_BOX;
  tank_shape.half_extents.x = 0.5f;
  tank_shape.half_extents.y = 0.3f;
  tank_shape.half_extents.z = 0.15f;
  tank_shape.voxel_size = 0.01f;
  if (sample_failed(sph_sdf_create_shape(context, &tank_shape, &tank_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&tank);
  tank.sdf = tank_sdf;
  tank.flags = SPH_COLLIDER_FLAG_INVERTED;
  tank.transform = sph_transform_identity();
  tank.transform.position.y = 0.3f;
  if (sample_failed(sph_collider_create(world, &tank, &tank_id), "sph_collider_create")) goto done;

  /* The water column against the left wall. */
  sph_fill_box_desc_init(&column);
  column.min.x = -0.5f;
  column.min.y = 0.0f;
  column.min.z = -0.15f;
  column.max.x = -0.15f;
  column.max.y = 0.5f;
  column.max.z = 0.15f;
  if (sample_failed(sph_world_fill_box(world, &column, &count), "sph_world_fill_box")) goto done;

  printf("dam_break: %u particles, %d frames -> %s/\n", count, frames, out_dir);
  if (sample_write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    if (sample_failed(sph_world_step(world, 1.0f / 60.0f), "sph_world_step")) goto done;
    if (sample_write_frame(world, out_dir, frame)) goto done;
    sph_stats_init(&stats);
    sph_world_get_stats(world, &stats);
    if (frame % 30 == 0 || frame == frames)
      printf("frame %3d/%d  substeps %3u  max speed %5.2f m/s  %6.1f ms\n", frame, frames, stats.substeps,
             stats.max_speed, stats.step_ms);
  }
  status = 0;

done:
  sph_sdf_destroy(tank_sdf); /* the collider keeps its own reference */
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
