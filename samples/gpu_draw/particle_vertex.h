// SPDX-License-Identifier: MIT
/* One particle as the renderer draws it (16 bytes: the size of the world's position records, so
 * a copy kernel reads one record and writes one vertex), and the colour it gets from its speed.
 * Shared by the CUDA kernel (gpu_draw_interop.cu) and the host path (gl_draw_host.c), so both
 * paint the same picture from the same particles. */
#ifndef SPH_SAMPLE_PARTICLE_VERTEX_H
#define SPH_SAMPLE_PARTICLE_VERTEX_H

#include <math.h>
#include <stdint.h>

#ifdef __CUDACC__
#define PARTICLE_VERTEX_HD __host__ __device__
#else
#define PARTICLE_VERTEX_HD
#endif

typedef struct particle_vertex {
  float x, y, z; /* m, world frame */
  uint32_t rgba; /* bytes R, G, B, A in memory order (GL_UNSIGNED_BYTE x 4, normalised) */
} particle_vertex;

/* Speeds at and above this are drawn white (m/s): a 0.5 m column falling freely reaches
 * sqrt(2 g 0.5) = 3.1 m/s. */
#define PARTICLE_VERTEX_WHITE_SPEED 3.0f

/* Deep blue at rest, through cyan, to white at PARTICLE_VERTEX_WHITE_SPEED. */
static inline PARTICLE_VERTEX_HD uint32_t particle_vertex_colour(float vx, float vy, float vz) {
  const float speed2 = vx * vx + vy * vy + vz * vz;
  const float white2 = PARTICLE_VERTEX_WHITE_SPEED * PARTICLE_VERTEX_WHITE_SPEED;
  const float t = speed2 >= white2 ? 1.0f : sqrtf(speed2 / white2);
  float r, g, b;
  if (t < 0.5f) { /* deep blue (0.08, 0.25, 0.75) -> cyan (0.25, 0.75, 0.95) */
    const float u = 2.0f * t;
    r = 0.08f + 0.17f * u;
    g = 0.25f + 0.50f * u;
    b = 0.75f + 0.20f * u;
  } else { /* cyan -> white */
    const float u = 2.0f * t - 1.0f;
    r = 0.25f + 0.75f * u;
    g = 0.75f + 0.25f * u;
    b = 0.95f + 0.05f * u;
  }
  return (uint32_t)(r * 255.0f + 0.5f) | ((uint32_t)(g * 255.0f + 0.5f) << 8) |
         ((uint32_t)(b * 255.0f + 0.5f) << 16) | (255u << 24);
}

#endif
