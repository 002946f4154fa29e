// SPDX-License-Identifier: MIT
/* What gpu_draw (CUDA-GL interop) and gl_draw_host (the host copy) share: the dam break they
 * draw, the camera that frames its tank, and the PNG of each frame. */
#ifndef SPH_SAMPLE_DRAW_SCENE_H
#define SPH_SAMPLE_DRAW_SCENE_H

#include <stdint.h>

#include "particle_renderer.h"
#include "sph_c.h"

#define DRAW_SCENE_WIDTH 640
#define DRAW_SCENE_HEIGHT 360

typedef struct draw_scene {
  sph_context* context;
  sph_world* world;
  sph_sdf* tank_sdf;
  uint32_t count;    /* particles after the fill */
  uint32_t capacity; /* the world's capacity: the vertex buffer's size */
  float spacing;     /* m */
} draw_scene;

/* A context on `backend` and samples/dam_break.c's scene (a 1 m x 0.6 m x 0.3 m tank, a
 * 0.35 m x 0.5 m column) at `spacing`. Returns 0 or 1 (reported); *s holds what was made. */
int draw_scene_open(sph_backend backend, float spacing, draw_scene* s);
void draw_scene_close(draw_scene* s);

/* The renderer for this scene: DRAW_SCENE_WIDTH x DRAW_SCENE_HEIGHT, the tank in view from the
 * front and a little above, sprites of the particle spacing. */
void draw_scene_renderer_def(const draw_scene* s, int cuda_device, particle_renderer_def* def);

/* Writes DIR/frame_NNNN.png from a bottom-up RGBA image of the scene's size. Returns 0 or 1. */
int draw_scene_write_png(const char* dir, int frame, const uint8_t* rgba);

#endif
