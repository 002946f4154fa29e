// SPDX-License-Identifier: MIT
/* The default demo scene, a dam break, built through the C API alone as an engine would
 * (the same scene as samples/scenes/dam_break.json, which sph-run plays): a column of water
 * collapses in a closed tank, an inverted box collider. The tank and the column come from
 * support_dam_break (tests/support/tank.c: a box SDF from sph_sdf_create_shape placed with
 * SPH_COLLIDER_FLAG_INVERTED, then sph_world_fill_box), the builder the tests and the dam-break
 * benchmark use. Every frame's particles are written as CSV (id, x, y, z, vx, vy, vz, density) to
 * the output directory.
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
#include "support.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/dam_break_c";
  int frames = 120, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  /* The tank: inside 1 m x 0.6 m x 0.3 m, the floor at y = 0; an SDF of 1 cm voxels. */
  const support_tank tank = {{0.0f, 0.3f, 0.0f}, {0.5f, 0.3f, 0.15f}, 0.01f, 0.0f};
  /* The water column against the left wall. */
  const sph_vec3 column_min = {-0.5f, 0.0f, -0.15f}, column_max = {-0.15f, 0.5f, 0.15f};
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

  if (sample_failed(support_dam_break(context, world, &tank, column_min, column_max, &tank_sdf, NULL, &count),
                    "support_dam_break"))
    goto done;

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
