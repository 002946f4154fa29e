// SPDX-License-Identifier: MIT
/* The hydrostatic tank's pressure-force moment and virial pressure per slice (hydrostatic_tank_moment.c
 * says what they are and why they are reported). */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_MOMENT_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_MOMENT_H

#include <stdint.h>

typedef struct tank_moment tank_moment;

/* corrected: the run's solves use SPH_DFSPH_CORRECTED_GRADIENT; the moment, the acceleration and
 * its zeroth-order part are then those of the corrected operator (hydrostatic_tank_moment.c). */
tank_moment* tank_moment_create(uint32_t bins, int corrected);
/* Adds one frame: the interior particles (h from the side walls) of each slice `bin` thick;
 * x: positions (xyz), p: the particles' pressure, rho: their density; step: the
 * lattice's (the kernel's scale). */
void tank_moment_add(tank_moment* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0, double h, double width, double bin, double step);
/* Prints per slice (y: the slices' mean heights) the mean M_yy, the pairs' pressure acceleration
 * and its zeroth-order part over g, and the virial pressure against rho0 g (surface - y). */
void tank_moment_print(const tank_moment* t, const double* y, double surface, double rho0, double g,
                       double h);
void tank_moment_destroy(tank_moment* t);

#endif
