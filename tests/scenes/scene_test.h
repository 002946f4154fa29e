// SPDX-License-Identifier: MIT
/* Helpers shared by the scene tests: a world on the test backend with chosen parameters, a
 * particle's state by id, and shape assets, over tests/support's worlds and readers. */
#ifndef SPH_SCENE_TEST_H
#define SPH_SCENE_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sph_c.h"
#include "support.h"

/* context, world, params (and def, mass): tests/support's world */
typedef support_world scene;

/* A context on the test backend and a world of `capacity` at `spacing`; params default but
 * gravity and dt_max as given. Fails the test on error. */
void scene_open(scene* s, uint32_t capacity, float spacing, float gravity_y, float dt_max);
void scene_close(scene* s);
void scene_set_params(scene* s);

/* An analytic shape asset; fails the test on error. */
sph_sdf* scene_shape(scene* s, const sph_shape_desc* desc);
sph_transform scene_at(float x, float y, float z);

/* Copies positions/velocities/ids out (arrays of the particle count). Returns the count. */
uint32_t scene_positions(scene* s, float* positions, uint32_t max);
uint32_t scene_velocities(scene* s, float* velocities, uint32_t max);
uint32_t scene_ids(scene* s, uint32_t* ids, uint32_t max);

/* Spawns one particle; returns its id. */
uint32_t scene_spawn_one(scene* s, float x, float y, float z, float vx, float vy, float vz);
/* Position and velocity of the particle with id `id`; fails the test if it is gone. */
void scene_particle(scene* s, uint32_t id, float position[3], float velocity[3]);

#define SCENE_OK(call) scene_ok((call), #call, __FILE__, __LINE__)
void scene_ok(sph_result r, const char* call, const char* file, int line);

#endif
