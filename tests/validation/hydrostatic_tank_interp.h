// SPDX-License-Identifier: MIT
/* The hydrostatic tank's brute-force check of its two pressure readings (docs/validation.md,
 * "DFSPH: hydrostatic tank", session 18): the probes' interpolant recomputed by hand from the
 * particles' positions, densities and pressures, and the height it reads the pressure at. */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_INTERP_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_INTERP_H

#include <stdint.h>

typedef struct tank_interp tank_interp;

tank_interp* tank_interp_create(uint32_t bins, double width, double depth, double h, double bin, double step);

/* One settled state: every gauge line of tank_gauges (bin mid-heights, lines along x every
 * lattice step in z, samples h / 8 apart) evaluated by hand, W_poly6, with V_j = m / rho_j. */
void tank_interp_add(tank_interp* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0);

/* Per slice: the Shepard interpolant of p, of y (the height the reading refers to) and of the
 * exact field, over the states added. */
void tank_interp_profile(const tank_interp* t, double* pressure, double* y_weighted, uint32_t* count);

void tank_interp_print(const tank_interp* t, const double* gauge_p, double surface, double rho0, double g);

void tank_interp_destroy(tank_interp* t);

#endif
