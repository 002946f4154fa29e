// SPDX-License-Identifier: MIT
/* gpu_draw: draws a CUDA world's particles straight from its device buffers, with no copy
 * through the host, and writes each frame as a PNG (issue 21, item 5; docs/embedding.md,
 * "Drawing from the GPU").
 *
 * A dam break (samples/dam_break.c's scene at 1 cm, 72 030 particles) steps on the CUDA
 * backend. A headless EGL context on the world's GPU (EGL_EXT_platform_device, the EGL device
 * whose EGL_CUDA_DEVICE_NV is the world's device) holds an OpenGL vertex buffer that CUDA maps
 * (cudaGraphicsGLRegisterBuffer); a kernel turns the world's positions and velocities
 * (sph_cuda_world_get_attribute) into coloured vertices in it, ordered against the world's
 * stream with events; GL draws them as sprites into a framebuffer object; glReadPixels gives
 * the image (the picture is the only thing that reaches the host). Each frame:
 *
 *   sph_world_step_wait                        the world holds frame f
 *   draw_interop_fill                          map, wait for the world, kernel, unmap, the
 *                                              world waits for the kernel (no host wait)
 *   sph_world_step_begin                       frame f + 1 runs on the world's thread ...
 *   particle_renderer_draw + PNG               ... while frame f is drawn and written
 *
 * Usage: gpu_draw [OUTPUT_DIR] [--frames N]   (default out/gpu_draw, 30 frames at 60 fps)
 * Writes OUTPUT_DIR/frame_0000.png .. frame_NNNN.png (640 x 360), then reads the last frame's
 * vertices back from GL and checks them against the world's positions (exit 1 if any differs).
 * Exits 77 when there is no CUDA device or no EGL device for it (scripts/gpu-test runs it on a
 * GPU machine). */
#include <cuda_runtime_api.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "draw_scene.h"
#include "gpu_draw_interop.h"
#include "sample_io.h"
#include "sph_cuda.h"

/* The last frame's vertices, read back from GL, against the world's positions copied through the
 * host (no step is in flight then): the interop path must hand GL exactly the world's floats. A
 * picture can look plausible with stale or missing vertices; this names which side went wrong
 * when png_check finds a blank image. Returns 0 when all count vertices match bit for bit. */
static int check_last_frame(particle_renderer* renderer, const draw_scene* scene, uint32_t count) {
  const size_t slots = count ? count : 1; /* (malloc(0) may give NULL) */
  particle_vertex* vertices = (particle_vertex*)malloc(sizeof(particle_vertex) * slots);
  float* positions = (float*)malloc(12 * slots);
  uint32_t i, differ = 0, first = 0, n = 0;
  int failed = !vertices || !positions;
  failed =
      failed || sample_failed(sph_world_get_particle_count(scene->world, &n), "sph_world_get_particle_count");
  if (!failed && n != count) {
    fprintf(stderr, "gpu_draw: the last frame drew %u vertices, the world holds %u particles\n", count, n);
    failed = 1;
  }
  failed = failed || particle_renderer_read_vertices(renderer, count, vertices) ||
           sample_failed(sph_world_copy_attribute(scene->world, SPH_ATTRIBUTE_POSITION, positions, 12 * slots,
                                                  0, 0, count, NULL),
                         "sph_world_copy_attribute");
  for (i = 0; !failed && i < count; ++i) {
    const float* x = positions + 3 * i;
    if (memcmp(&vertices[i].x, x, 12) != 0 && differ++ == 0) first = i;
  }
  if (!failed && differ > 0) {
    const float* x = positions + 3 * first;
    fprintf(stderr,
            "gpu_draw: %u of %u vertices in GL's buffer differ from the world's positions (first: vertex %u "
            "(%g, %g, %g), particle (%g, %g, %g))\n",
            differ, count, first, vertices[first].x, vertices[first].y, vertices[first].z, x[0], x[1], x[2]);
    failed = 1;
  }
  if (!failed) printf("last frame: the %u vertices GL drew equal the world's positions bit for bit\n", count);
  free(vertices);
  free(positions);
  return failed;
}

int main(int argc, char** argv) {
  const char* out_dir = "out/gpu_draw";
  int frames = 30, frame, status, devices = 0;
  int32_t device = -1;
  sph_backend backend = SPH_BACKEND_CUDA;
  draw_scene scene;
  particle_renderer_def def;
  particle_renderer* renderer = NULL;
  draw_interop* interop = NULL;
  uint8_t* rgba = NULL;
  int stepping = 0;
  uint32_t count = 0;

  status = sample_parse_args(argc, argv, "gpu_draw", &out_dir, &frames, &backend);
  if (status != 0) return status;
  if (backend != SPH_BACKEND_CUDA && backend != SPH_BACKEND_AUTO) {
    fprintf(stderr, "gpu_draw: draws from device memory: the CUDA backend only (gl_draw_host copies)\n");
    return 2;
  }
  if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
    fprintf(stderr, "gpu_draw: no CUDA device\n");
    return 77;
  }
  if (draw_scene_open(SPH_BACKEND_CUDA, 0.01f, &scene) ||
      sample_failed(sph_cuda_world_get_device(scene.world, &device), "sph_cuda_world_get_device")) {
    draw_scene_close(&scene);
    return 1;
  }
  /* The GL context on the world's GPU, made current on this thread; CUDA on the same device. */
  draw_scene_renderer_def(&scene, device, &def);
  status = particle_renderer_create(&def, &renderer);
  if (status != 0) {
    draw_scene_close(&scene);
    return status;
  }
  status = 1;
  if (cudaSetDevice(device) != cudaSuccess ||
      draw_interop_create(particle_renderer_vertex_buffer(renderer), scene.capacity, &interop))
    goto done;
  rgba = (uint8_t*)malloc(4 * (size_t)DRAW_SCENE_WIDTH * DRAW_SCENE_HEIGHT);
  if (!rgba) goto done;
  printf("gpu_draw: %u particles on CUDA device %d, %s on %s, %d frames -> %s/\n", scene.count, (int)device,
         particle_renderer_api(renderer), particle_renderer_device(renderer), frames, out_dir);

  for (frame = 0; frame <= frames; ++frame) {
    count = 0;
    if (draw_interop_fill(interop, scene.world, &count)) goto done;
    if (frame < frames) { /* the next frame runs while this one is drawn */
      if (sample_failed(sph_world_step_begin(scene.world, 1.0f / 60.0f), "sph_world_step_begin")) goto done;
      stepping = 1;
    }
    if (particle_renderer_draw(renderer, count, rgba) || draw_scene_write_png(out_dir, frame, rgba))
      goto done;
    if (stepping) {
      stepping = 0;
      if (sample_failed(sph_world_step_wait(scene.world), "sph_world_step_wait")) goto done;
    }
    if (frame % 10 == 0 || frame == frames)
      printf("frame %3d/%d  %u particles drawn\n", frame, frames, count);
  }
  if (check_last_frame(renderer, &scene, count)) goto done;
  status = 0;

done:
  if (stepping) sph_world_step_wait(scene.world); /* a world is destroyed only after its wait */
  draw_interop_destroy(interop);                  /* before the GL context goes */
  particle_renderer_destroy(renderer);
  free(rgba);
  draw_scene_close(&scene);
  return status;
}
