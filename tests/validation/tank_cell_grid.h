// SPDX-License-Identifier: MIT
/* A cell grid h wide over particles' bounding box, for the hydrostatic tank's brute-force sums
 * (hydrostatic_tank_moment.c, hydrostatic_tank_interp.c): the particles of the 27 cells around a
 * point, in a fixed order (cell by cell, z then y then x outermost to innermost, each cell's
 * particles by index). */
#pragma once

#include <stdint.h>

typedef struct tank_cell_grid {
  double lo[3], h;
  int dims[3];
  uint32_t *start, *order, *candidates;
} tank_cell_grid;

void tank_cell_grid_build(tank_cell_grid* g, const float* x, uint32_t n, double h);
/* The particles in the cells around q (g->candidates, valid until the next call): their count. */
uint32_t tank_cell_grid_near(tank_cell_grid* g, const double q[3]);
void tank_cell_grid_free(tank_cell_grid* g);
