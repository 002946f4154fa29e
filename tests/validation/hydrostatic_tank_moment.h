// SPDX-License-Identifier: MIT
/* The hydrostatic tank's pressure-force moment and virial pressure per slice (hydrostatic_tank_moment.c
 * says what they are and why they are reported). */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_MOMENT_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_MOMENT_H

#include <stdint.h>

typedef struct tank_moment tank_moment;

tank_moment* tank_moment_create(uint32_t bins);
/* Adds one frame: the interior particles (h from the side walls) of each slice `bin` thick;
 * x: positions (xyz), p: the particles' pressure, rho: their density; step: the
 * lattice's (the kernel's scale). */
void tank_moment_add(tank_moment* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0, double h, double width, double bin, double step);
/* Per slice: the mean M_yy, the mean virial pressure (Pa), the mean upward acceleration of the
 * pairs' pressure force (m/s^2; g at rest), the particle samples. */
void tank_moment_profile(const tank_moment* t, double* moment, double* virial, double* lift, uint32_t* count);
void tank_moment_destroy(tank_moment* t);

#endif
