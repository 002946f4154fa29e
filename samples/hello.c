// SPDX-License-Identifier: MIT
/* The smallest useful program: create a world, fill a box with water, step 100 frames and
 * print what happened. Build: cc hello.c $(pkg-config --cflags --libs sph) */
#include <stdio.h>

#include "sph_c.h"

static int check(sph_result r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "%s failed: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
    return 1;
  }
  return 0;
}

int main(void) {
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world_def world_def;
  sph_world* world = NULL;
  sph_fill_box_desc box;
  sph_stats stats;
  uint32_t count = 0;
  int frame;
  int failed = 0;

  sph_context_def_init(&context_def);
  context_def.backend = SPH_BACKEND_CPU;
  if (check(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def); /* water, 2 cm spacing */
  world_def.capacity = 20000;
  if (check(sph_world_create(context, &world_def, &world), "sph_world_create")) {
    sph_context_destroy(context);
    return 1;
  }

  sph_fill_box_desc_init(&box); /* a 20 cm cube of water; nothing holds it: it falls freely */
  box.min.x = 0.0f;
  box.min.y = 0.0f;
  box.min.z = 0.0f;
  box.max.x = 0.2f;
  box.max.y = 0.2f;
  box.max.z = 0.2f;
  failed |= check(sph_world_fill_box(world, &box, &count), "sph_world_fill_box");
  printf("filled %u particles\n", count);

  for (frame = 0; frame < 100 && !failed; ++frame)
    failed |= check(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");

  sph_stats_init(&stats);
  failed |= check(sph_world_get_stats(world, &stats), "sph_world_get_stats");
  printf(
      "t = %.3f s, %u particles, last frame: %u substeps, max speed %.3f m/s, "
      "density %.1f..%.1f kg/m^3 (mean %.1f), %.1f neighbours\n",
      stats.simulated_time, stats.particle_count, stats.substeps, stats.max_speed, stats.density_min,
      stats.density_max, stats.density_mean, stats.neighbors_mean);

  sph_world_destroy(world);
  sph_context_destroy(context);
  return failed;
}
