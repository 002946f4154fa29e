// SPDX-License-Identifier: MIT
/* The hydrostatic tank's pressure read through the library's gauges (hydrostatic_tank_gauges.c
 * says which and why), per slice of the particle reading. */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_GAUGES_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_GAUGES_H

#include <stdint.h>

#include "sph_c.h"

typedef struct tank_gauges tank_gauges;

/* Lines for each of `bins` slices `bin` thick whose mid-height is below `depth`, over
 * [h, width - h] in x, one every `step` in z from h. */
tank_gauges* tank_gauges_create(sph_world* world, double width, double depth, double h, double bin,
                                uint32_t bins, double step);
/* Adds the last step's readings (every substep's, averaged by the library). */
void tank_gauges_read(tank_gauges* g, const sph_world* world);
/* Per slice: the mean pressure read, the lines' height and the readings (0: no line). */
void tank_gauges_profile(const tank_gauges* g, double bin, double* pressure, double* y, uint32_t* count);
void tank_gauges_destroy(tank_gauges* g, sph_world* world);

#endif
