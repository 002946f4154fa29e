// SPDX-License-Identifier: MIT
/* Helpers of the extremes tests (issue 6 item 3): a world on the test backend, a small dam
 * break in a closed tank (both tests/support's), and the measurements that define a "stable
 * state" (finite values, particle count, speed and mechanical energy bounded by the drop, density
 * band, containment). */
#ifndef SPH_EXTREMES_UTIL_H
#define SPH_EXTREMES_UTIL_H

#include "capi_test.h"

#define EXT_G 9.81f

/* Fails the test (naming the call and the library's message) unless the call succeeded. */
#define EXT_OK(call) ext_ok((call), #call, __FILE__, __LINE__)
void ext_ok(sph_result r, const char* call, const char* file, int line);

/* context, world, def (kernel radius filled in), params, mass: tests/support's world */
typedef support_world ext_world;

/* A context on the test backend and a world of `capacity` at `spacing` (default params). */
void ext_open(ext_world* w, uint32_t capacity, float spacing);
/* The same with a whole def (its struct_size and header_version are set here). */
void ext_open_def(ext_world* w, sph_world_def def);
void ext_close(ext_world* w);
void ext_set_params(ext_world* w);

/* Spawns `count` particles from packed arrays (velocities may be NULL). */
void ext_spawn(ext_world* w, const float* positions, const float* velocities, uint32_t count);

/* Copies one attribute of every particle into a new malloc'ed buffer (NULL when empty). */
void* ext_copy(const sph_world* world, sph_attribute attribute, uint32_t* out_count);

/* What a run of a scene measured, over all the frames stepped. */
typedef struct ext_measure {
  uint32_t count;        /* particles at the end */
  int finite;            /* every position, velocity and density stayed finite */
  float max_speed;       /* fastest particle seen, m/s */
  float max_energy_gain; /* most the mechanical energy (kinetic + g y) rose above its start, J */
  float drop_energy;     /* sum of m g (y0 - floor): all the energy a fall can release, J */
  float density_max;     /* largest density seen, kg/m^3 */
  float worst_depth;     /* deepest any particle got beyond the tank's inner faces, m */
  float largest_dt;      /* largest substep any frame took, s */
  uint32_t substeps;     /* over all frames */
} ext_measure;

/* The tank: an inverted box collider whose cavity is [-hx, hx] x [0, 2 hy] x [-hz, hz], and a
 * column of water in its -x end, [-hx, -hx + column_width] x [0, column_height] x [-hz, hz]
 * (support_dam_break). */
typedef struct ext_tank {
  float hx, hy, hz;
  float column_width, column_height;
  sph_sdf* sdf;
  sph_collider_id collider;
} ext_tank;

void ext_tank_build(ext_world* w, ext_tank* t);
void ext_tank_destroy(ext_world* w, ext_tank* t);
/* Steps `frames` frames of frame_dt and measures (see ext_measure). */
ext_measure ext_tank_run(ext_world* w, const ext_tank* t, int frames, float frame_dt);

/* Mechanical energy sum(1/2 m v^2 + m g y) of the particles (g along -y). */
double ext_mechanical_energy(const sph_world* world, float mass, float g);

#endif
