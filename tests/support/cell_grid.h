// SPDX-License-Identifier: MIT
/* A cell grid h wide over particles' bounding box, for brute-force sums on the host (the
 * hydrostatic tank's moment and interpolant, tests/validation; the dam break's neighbour counts,
 * dam_break.c): the particles of the 27 cells around a point, in a fixed order (cell by cell, z
 * then y then x outermost to innermost, each cell's particles by index). */
#ifndef SPH_TESTS_CELL_GRID_H
#define SPH_TESTS_CELL_GRID_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct support_cell_grid {
  double lo[3], h;
  int dims[3];
  uint32_t *start, *order, *candidates;
} support_cell_grid;

/* Builds the grid over the n positions x (3 floats each, finite). Returns 0 when out of memory
 * (the grid then holds nothing to free), 1 otherwise. */
int support_cell_grid_build(support_cell_grid* g, const float* x, uint32_t n, double h);
/* The particles in the cells around q (g->candidates, valid until the next call): their count. */
uint32_t support_cell_grid_near(support_cell_grid* g, const double q[3]);
void support_cell_grid_free(support_cell_grid* g);

#ifdef __cplusplus
}
#endif

#endif
