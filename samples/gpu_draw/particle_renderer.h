// SPDX-License-Identifier: MIT
/* A headless particle renderer: an EGL context with no window system (headless_egl.h: the EGL
 * device of a CUDA device, or Mesa's surfaceless platform when no device is asked for), OpenGL
 * 3.3 core (OpenGL ES 3.0 where desktop GL is refused), a framebuffer object of the image size, and
 * a vertex buffer of particle_vertex that a CUDA kernel (through cudaGraphicsGLRegisterBuffer)
 * or the host fills. Each draw renders the particles as point sprites shaded as spheres and
 * reads the image back.
 *
 * GL entry points are loaded through eglGetProcAddress (EGL 1.5 returns core functions too):
 * the program links libEGL alone, not libOpenGL or libGLESv2, so one binary runs whichever of
 * the two APIs the driver gives, and a machine needs only glvnd's libEGL and libGLdispatch.
 *
 * The context is current on the thread that created the renderer; every call below and every
 * CUDA-GL interop call on its buffer must come from that thread. */
#ifndef SPH_SAMPLE_PARTICLE_RENDERER_H
#define SPH_SAMPLE_PARTICLE_RENDERER_H

#include <stdint.h>

#include "particle_vertex.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct particle_renderer particle_renderer;

typedef struct particle_renderer_def {
  int width, height;       /* image size in pixels */
  int cuda_device;         /* the EGL device whose EGL_CUDA_DEVICE_NV is this ordinal; -1: any */
  uint32_t capacity;       /* vertices the buffer holds */
  float particle_radius;   /* m: the sprites' size */
  float eye[3], target[3]; /* the camera (y up) */
  float fov_y_degrees;     /* vertical field of view */
} particle_renderer_def;

/* Creates the context (made current on this thread), the framebuffer, the shaders and the vertex
 * buffer. Returns 0, or 77 when no EGL display can be opened (no driver: a test skips), or 1 on
 * any other failure; both print why on stderr. */
int particle_renderer_create(const particle_renderer_def* def, particle_renderer** out);

/* The GL name of the vertex buffer (capacity particle_vertex, GL_DYNAMIC_DRAW): what a CUDA
 * program registers with cudaGraphicsGLRegisterBuffer. */
unsigned particle_renderer_vertex_buffer(const particle_renderer* renderer);

/* "OpenGL 3.3 core" or "OpenGL ES 3.0", and the GL_RENDERER string. */
const char* particle_renderer_api(const particle_renderer* renderer);
const char* particle_renderer_device(const particle_renderer* renderer);

/* The host path: copies count vertices into the buffer (glBufferSubData). Returns 0 or 1. */
int particle_renderer_upload(particle_renderer* renderer, const particle_vertex* vertices, uint32_t count);

/* Reads the first count vertices of the buffer back into out (glMapBufferRange for reading, which
 * both APIs have): what the GPU draws, for a program that checks a writer of the buffer (a CUDA
 * kernel through interop) against its source. Returns 0 or 1 (printed). */
int particle_renderer_read_vertices(particle_renderer* renderer, uint32_t count, particle_vertex* out);

/* Draws the first count vertices of the buffer and reads the image into rgba (width * height * 4
 * bytes, rows bottom to top as glReadPixels gives them). Returns 0 or 1 (a GL error, printed). */
int particle_renderer_draw(particle_renderer* renderer, uint32_t count, uint8_t* rgba);

/* Releases the GL objects, the context and the display (NULL is allowed). A CUDA registration
 * of the buffer must be released before. */
void particle_renderer_destroy(particle_renderer* renderer);

#ifdef __cplusplus
}
#endif

#endif
