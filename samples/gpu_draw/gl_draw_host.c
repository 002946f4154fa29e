// SPDX-License-Identifier: MIT
/* gl_draw_host: gpu_draw's picture through a host copy, for machines without a GPU (and CI):
 * the same dam break on any backend, its positions and velocities copied to the host with
 * sph_world_copy_attribute, turned into the same vertices (particle_vertex.h) and uploaded with
 * glBufferSubData, then drawn by the same renderer on whatever EGL gives (Mesa's llvmpipe
 * here). It tests the renderer and the PNG path; gpu_draw is the zero-copy program.
 *
 * Usage: gl_draw_host [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/gl_draw_host, 3 frames, the CPU backend). Writes frame_NNNN.png for
 *        frames 0..N; exits 77 when no EGL display can be opened. */
#include <stdio.h>
#include <stdlib.h>

#include "draw_scene.h"
#include "sample_io.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/gl_draw_host";
  int frames = 3, frame, status;
  sph_backend backend = SPH_BACKEND_CPU;
  draw_scene scene;
  particle_renderer_def def;
  particle_renderer* renderer = NULL;
  float *positions = NULL, *velocities = NULL;
  particle_vertex* vertices = NULL;
  uint8_t* rgba = NULL;

  status = sample_parse_args(argc, argv, "gl_draw_host", &out_dir, &frames, &backend);
  if (status != 0) return status;
  if (draw_scene_open(backend, 0.02f, &scene)) {
    draw_scene_close(&scene);
    return 1;
  }
  draw_scene_renderer_def(&scene, -1, &def);
  status = particle_renderer_create(&def, &renderer);
  if (status != 0) {
    draw_scene_close(&scene);
    return status; /* 77: no EGL display, the test skips */
  }
  printf("gl_draw_host: %u particles, %s on %s, %d frames -> %s/\n", scene.count,
         particle_renderer_api(renderer), particle_renderer_device(renderer), frames, out_dir);
  status = 1;
  positions = (float*)malloc(12 * (size_t)scene.capacity);
  velocities = (float*)malloc(12 * (size_t)scene.capacity);
  vertices = (particle_vertex*)malloc(sizeof(particle_vertex) * scene.capacity);
  rgba = (uint8_t*)malloc(4 * (size_t)DRAW_SCENE_WIDTH * DRAW_SCENE_HEIGHT);
  if (!positions || !velocities || !vertices || !rgba) goto done;
  for (frame = 0; frame <= frames; ++frame) {
    uint32_t n = 0, i;
    if (frame > 0 && sample_failed(sph_world_step(scene.world, 1.0f / 60.0f), "sph_world_step")) goto done;
    if (sample_failed(sph_world_get_particle_count(scene.world, &n), "sph_world_get_particle_count") ||
        sample_failed(sph_world_copy_attribute(scene.world, SPH_ATTRIBUTE_POSITION, positions,
                                               12ull * scene.capacity, 0, 0, n, NULL),
                      "sph_world_copy_attribute") ||
        sample_failed(sph_world_copy_attribute(scene.world, SPH_ATTRIBUTE_VELOCITY, velocities,
                                               12ull * scene.capacity, 0, 0, n, NULL),
                      "sph_world_copy_attribute"))
      goto done;
    for (i = 0; i < n; ++i) {
      const float* x = positions + 3 * i;
      const float* v = velocities + 3 * i;
      vertices[i].x = x[0];
      vertices[i].y = x[1];
      vertices[i].z = x[2];
      vertices[i].rgba = particle_vertex_colour(v[0], v[1], v[2]);
    }
    if (particle_renderer_upload(renderer, vertices, n) || particle_renderer_draw(renderer, n, rgba) ||
        draw_scene_write_png(out_dir, frame, rgba))
      goto done;
  }
  printf("gl_draw_host: wrote %s/frame_0000.png .. frame_%04d.png\n", out_dir, frames);
  status = 0;

done:
  free(rgba);
  free(vertices);
  free(velocities);
  free(positions);
  particle_renderer_destroy(renderer);
  draw_scene_close(&scene);
  return status;
}
