// SPDX-License-Identifier: MIT
/* FCC lattices: the points of a ball (those of sph_world_fill_sphere) and a box tiled exactly. */
#include <math.h>
#include <stdlib.h>

#include "support.h"

/* The points of the ball, written to p when it is not NULL; returns their count. */
static uint64_t sphere_points(const double centre[3], double radius, double spacing, float* p) {
  const double step = spacing / sqrt(2.0);
  const int64_t n = (int64_t)floor(radius / step);
  const double r2 = radius * radius;
  uint64_t count = 0;
  for (int64_t k = -n; k <= n; ++k)
    for (int64_t j = -n; j <= n; ++j)
      for (int64_t i = -n; i <= n; ++i) {
        const double x = step * (double)i, y = step * (double)j, z = step * (double)k;
        if (((i + j + k) % 2 + 2) % 2 != 0) continue;
        if (x * x + y * y + z * z > r2) continue;
        if (p) {
          p[3 * count] = (float)(centre[0] + x);
          p[3 * count + 1] = (float)(centre[1] + y);
          p[3 * count + 2] = (float)(centre[2] + z);
        }
        ++count;
      }
  return count;
}

sph_result support_fcc_sphere(const double* centre, double radius, double spacing, float** positions,
                              uint32_t* count) {
  static const double origin[3] = {0.0, 0.0, 0.0};
  const double* c = centre ? centre : origin;
  uint64_t n;
  float* p;
  *positions = NULL;
  *count = 0;
  if (!(spacing > 0.0) || !(radius >= 0.0) || radius / spacing > 1e6) return SPH_ERROR_INVALID_ARGUMENT;
  n = sphere_points(c, radius, spacing, NULL);
  p = (float*)malloc(sizeof(float) * 3 * (size_t)(n + 1));
  if (p == NULL || n > UINT32_MAX) {
    free(p);
    return SPH_ERROR_OUT_OF_HOST_MEMORY;
  }
  sphere_points(c, radius, spacing, p);
  *positions = p;
  *count = (uint32_t)n;
  return SPH_OK;
}

sph_result support_fcc_box(const uint32_t layers[3], double step, const double* origin, float** positions,
                           uint32_t* count) {
  static const double zero[3] = {0.0, 0.0, 0.0};
  const double* o = origin ? origin : zero;
  const uint64_t cells = (uint64_t)layers[0] * layers[1] * layers[2];
  float* p = (float*)malloc(sizeof(float) * 3 * (size_t)(cells + 1));
  uint32_t n = 0;
  *positions = NULL;
  *count = 0;
  if (p == NULL) return SPH_ERROR_OUT_OF_HOST_MEMORY;
  for (uint32_t k = 0; k < layers[2]; ++k)
    for (uint32_t j = 0; j < layers[1]; ++j)
      for (uint32_t i = 0; i < layers[0]; ++i) {
        if ((i + j + k) % 2) continue;
        p[3 * n] = (float)(o[0] + (i + 0.5) * step);
        p[3 * n + 1] = (float)(o[1] + (j + 0.5) * step);
        p[3 * n + 2] = (float)(o[2] + (k + 0.5) * step);
        ++n;
      }
  *positions = p;
  *count = n;
  return SPH_OK;
}
