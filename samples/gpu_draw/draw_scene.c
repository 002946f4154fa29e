// SPDX-License-Identifier: MIT
#include "draw_scene.h"

#include <stdio.h>
#include <string.h>

#include "png_image.h"
#include "sample_io.h"
#include "support.h"

int draw_scene_open(sph_backend backend, float spacing, draw_scene* s) {
  const support_tank tank = {{0.0f, 0.3f, 0.0f}, {0.5f, 0.3f, 0.15f}, 0.01f, 0.0f};
  const sph_vec3 column_min = {-0.5f, 0.0f, -0.15f}, column_max = {-0.15f, 0.5f, 0.15f};
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  memset(s, 0, sizeof *s);
  s->spacing = spacing;
  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &s->context), "sph_context_create")) return 1;
  sph_world_def_init(&world_def);
  /* The fill's lattice puts 1.24 particles in a spacing cube of the column (8160 at 2 cm): room
   * for 1.5 and a few more. */
  world_def.capacity = (uint32_t)(1.5f * 0.35f * 0.5f * 0.3f / (spacing * spacing * spacing)) + 1000u;
  world_def.particle_spacing = spacing;
  if (sample_failed(sph_world_create(s->context, &world_def, &s->world), "sph_world_create")) return 1;
  s->capacity = world_def.capacity;
  sph_world_params_init(&params);
  if (sample_failed(sph_world_set_params(s->world, &params), "sph_world_set_params")) return 1;
  return sample_failed(
      support_dam_break(s->context, s->world, &tank, column_min, column_max, &s->tank_sdf, NULL, &s->count),
      "support_dam_break");
}

void draw_scene_close(draw_scene* s) {
  sph_sdf_destroy(s->tank_sdf);
  sph_world_destroy(s->world);
  sph_context_destroy(s->context);
  memset(s, 0, sizeof *s);
}

void draw_scene_renderer_def(const draw_scene* s, int cuda_device, particle_renderer_def* def) {
  const particle_renderer_def d = {DRAW_SCENE_WIDTH,   DRAW_SCENE_HEIGHT,    cuda_device,         s->capacity,
                                   0.55f * s->spacing, {0.0f, 0.55f, 1.25f}, {0.0f, 0.22f, 0.0f}, 40.0f};
  *def = d;
}

int draw_scene_write_png(const char* dir, int frame, const uint8_t* rgba) {
  char path[4200];
  snprintf(path, sizeof path, "%s/frame_%04d.png", dir, frame);
  return png_image_write_bottom_up(path, DRAW_SCENE_WIDTH, DRAW_SCENE_HEIGHT, rgba);
}
