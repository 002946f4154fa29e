/* Helpers of the validation cases (tests/validation): the resolution switch between CI and the
 * full run, a lattice that tiles a box exactly, a closed tank, and plain statistics. They drive
 * the library through the C API only. */
#ifndef SPH_VALIDATION_UTIL_H
#define SPH_VALIDATION_UTIL_H

#include <stdint.h>
#include <stdio.h>

#include "physics_util.h"

/* 1 when SPH_VALIDATION_FULL=1 asks for the full resolution (scripts/validate --full), else 0:
 * the reduced resolution CI runs. */
int validation_full(void);

/* Where a case writes its results for scripts/validate (SPH_VALIDATION_OUT, a folder), or NULL
 * when unset. validation_open_output opens `name` there for writing, or returns NULL. */
const char* validation_output_dir(void);
FILE* validation_open_output(const char* name);

/* FCC points tiling the box [0, n[0] step) x [0, n[1] step) x [0, n[2] step) (+ origin) with no
 * gap at the faces: the simple-cubic points (i + 1/2) step with an even index sum, so every
 * particle stands for the volume 2 step^3 = spacing^3 / sqrt 2 of the world's FCC lattice at
 * spacing = step sqrt 2, and the box holds exactly its volume at rest density. Returns the
 * count; *positions is malloc'd. */
uint32_t validation_lattice_box(const uint32_t n[3], double step, const double origin[3], float** positions);

/* A closed box [min, max] as an inverted collider (the inside is the fluid's space). */
sph_collider_id validation_tank(sph_context* context, sph_world* world, const double min[3],
                                const double max[3], double voxel, float friction, sph_sdf** out_sdf);

/* Kinetic energy of all particles (J). */
double validation_kinetic_energy(const sph_world* world, float mass);

#endif
