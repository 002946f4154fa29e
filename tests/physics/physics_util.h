/* Helpers of the physics tests, which drive the library through the C API only. */
#ifndef SPH_PHYSICS_UTIL_H
#define SPH_PHYSICS_UTIL_H

#include <stddef.h>

#include "capi_test.h"

/* A context on the test backend and a world from def; fails the test on error. */
void physics_create(const sph_world_def* def, sph_context** context, sph_world** world);
void physics_destroy(sph_context* context, sph_world* world);

/* Copies every particle's attribute into a malloc'd array (3 floats per particle for
 * position/velocity, 1 float or uint32 otherwise) ordered by particle id, so that arrays from
 * different calls line up. Returns the particle count. */
uint32_t physics_copy_by_id(const sph_world* world, sph_attribute attribute, void** out);

/* The FCC points sph_world_fill_sphere makes for this spacing (from a scratch world). */
uint32_t physics_fcc_sphere(float spacing, float radius, float** positions);

/* Spawns n particles at positions with every velocity component uniform in
 * [-disturbance, disturbance] m/s (sph_test_random from *rng, so runs repeat); returns their
 * kinetic energy, sum 0.5 m v^2 in double. */
double physics_spawn_disturbed(sph_world* world, const float* positions, uint32_t n, double disturbance,
                               uint64_t* rng);

/* Sets gravity, dt limits and keeps the other params at their defaults. */
void physics_set_params(sph_world* world, float gx, float gy, float gz, float dt_min, float dt_max);

#endif /* SPH_PHYSICS_UTIL_H */
