// SPDX-License-Identifier: MIT
#include "cell_grid.h"

#include <math.h>
#include <stdlib.h>

int support_cell_grid_build(support_cell_grid* g, const float* x, uint32_t n, double h) {
  uint32_t cells, *cell_of, *fill;
  g->h = h;
  for (int a = 0; a < 3; ++a) {
    double lo = 1e30, hi = -1e30;
    for (uint32_t i = 0; i < n; ++i) {
      lo = fmin(lo, x[3 * i + a]);
      hi = fmax(hi, x[3 * i + a]);
    }
    g->lo[a] = lo;
    g->dims[a] = (int)((hi - lo) / h) + 1;
  }
  cells = (uint32_t)(g->dims[0] * g->dims[1] * g->dims[2]);
  g->start = (uint32_t*)calloc(cells + 1u, sizeof(uint32_t));
  g->order = (uint32_t*)malloc(sizeof(uint32_t) * (n + 1u));
  g->candidates = (uint32_t*)malloc(sizeof(uint32_t) * (n + 1u));
  cell_of = (uint32_t*)malloc(sizeof(uint32_t) * (n + 1u));
  fill = (uint32_t*)malloc(sizeof(uint32_t) * cells);
  if (!g->start || !g->order || !g->candidates || !cell_of || !fill) {
    support_cell_grid_free(g);
    free(cell_of);
    free(fill);
    return 0;
  }
  for (uint32_t i = 0; i < n; ++i) {
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = (int)((x[3 * i + a] - g->lo[a]) / h);
    cell_of[i] = (uint32_t)((c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0]);
    ++g->start[cell_of[i] + 1u];
  }
  for (uint32_t c = 0; c < cells; ++c) g->start[c + 1u] += g->start[c];
  for (uint32_t c = 0; c < cells; ++c) fill[c] = g->start[c];
  for (uint32_t i = 0; i < n; ++i) g->order[fill[cell_of[i]]++] = i;
  free(cell_of);
  free(fill);
  return 1;
}

uint32_t support_cell_grid_near(support_cell_grid* g, const double q[3]) {
  uint32_t count = 0;
  int c[3];
  for (int a = 0; a < 3; ++a) c[a] = (int)floor((q[a] - g->lo[a]) / g->h);
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
        uint32_t cell;
        if (cx < 0 || cy < 0 || cz < 0 || cx >= g->dims[0] || cy >= g->dims[1] || cz >= g->dims[2]) continue;
        cell = (uint32_t)((cz * g->dims[1] + cy) * g->dims[0] + cx);
        for (uint32_t e = g->start[cell]; e < g->start[cell + 1u]; ++e) g->candidates[count++] = g->order[e];
      }
  return count;
}

void support_cell_grid_free(support_cell_grid* g) {
  free(g->start);
  free(g->order);
  free(g->candidates);
  g->start = g->order = g->candidates = NULL;
}
