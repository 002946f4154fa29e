// SPDX-License-Identifier: MIT
/* tests/support: the scenes and helpers that the tests, the benchmarks and the samples share, so
 * each is written once: the test backend switch, a deterministic random generator, FCC lattices
 * (a ball, a box tiled exactly), a world from a def and params, spawning, reading attributes in
 * storage order or by particle id, the rest sphere, the closed tank, the dam break column in a
 * tank. The Martin & Moyce dam-break case (a complete run and its comparison with the
 * measurements) is dam_break.h, here too, and a host cell grid for brute-force sums is
 * cell_grid.h.
 *
 * Plain C99 on the public API (sph_c.h) only, no test framework: C tests, C++ tests, the
 * benchmarks and the samples all link it (CMake target sph_support). Every function that calls
 * the library returns sph_result: SPH_OK, or the result of the first call that failed, with that
 * call's message still in sph_get_last_error() (no library call follows a failure). Each caller
 * reports failures its own way (cmocka's EXPECT_OK, a benchmark's check(), the GPU checks'
 * require_ok()). Results are bit for bit those of the code they replaced: the lattices, the
 * random numbers and the sums run in the same order with the same arithmetic. */
#ifndef SPH_TESTS_SUPPORT_H
#define SPH_TESTS_SUPPORT_H

#include <stddef.h>
#include <stdint.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- backends and contexts ------------------------------------------------------------------ */

/** The backend named by the environment variable SPH_TEST_BACKEND (cpu | cuda | auto; unset or
 * empty: cpu), so the GPU test script can rerun the C-API tests on the CUDA backend. An unknown
 * name prints a message and exits with 2. */
sph_backend sph_test_backend(void);
/** "cpu", "cuda" or "auto": the value sph_test_backend() was read from. */
const char* sph_test_backend_name(void);
/** sph_context_def_init() with the test backend filled in. */
sph_result sph_test_context_def_init(sph_context_def* def);
/* sph_context_def.cuda_dfsph_masks from SPH_TEST_CUDA_DFSPH_MASKS (on, off or lists; unset: the
 * default), which support_context_def_init (and so the other context helpers) applies; exits 2 on another
 * value. A CPU context ignores it. */
uint32_t sph_test_cuda_dfsph_masks(void);
/** Creates a context on the test backend with defaults otherwise. */
sph_result sph_test_context_create(sph_context** out);

/** The name of sph_stats.stage_ms's entry `stage` (SPH_STAGE_HASH_SORT ...: "hash_sort", "cell_ranges",
 * "density", "forces", "integrate", "collide", "emit", "other"), as the benchmarks print and write
 * it; "?" out of range. */
const char* support_stage_name(int stage);

/** The backend a command line names: "cpu", "cuda" or "auto"; `otherwise` for anything else
 * (NULL included). */
sph_backend support_backend_from_name(const char* name, sph_backend otherwise);
/** sph_context_def_init() with `backend` and the tests' DFSPH masks setting filled in. */
sph_result support_context_def_init(sph_backend backend, sph_context_def* def);
/** Creates a context on `backend` with defaults otherwise. */
sph_result support_context_create(sph_backend backend, sph_context** out);

/* ---- deterministic random numbers ----------------------------------------------------------- */

/** A number in [0, 1) from xorshift64* (53 bits), advancing *state: every run and platform sees
 * the same sequence. *state must not be 0. */
double support_random(uint64_t* state);
/** Fills 3 * count velocity components, each (float)(speed * (2 u - 1)) with u from
 * support_random, i.e. uniform in [-speed, speed], in the order x, y, z of particle 0, then 1,
 * ...; with `drift` (3 floats, or NULL) each component is drift[k] + that, added in float. */
void support_random_velocities(float* velocities, uint32_t count, double speed, const float* drift,
                               uint64_t* state);
/** Moves each of 3 * count coordinates by (float)(amplitude * (2 u - 1)), u in [0, 1) from a 64-bit
 * linear congruential generator seeded with `seed` (another sequence than support_random's): the
 * rounding-sized nudges the validation and loads measurements call draws (seed N, 1e-7 m). */
void support_nudge(float* xyz, uint32_t count, uint64_t seed, double amplitude);

/* ---- FCC lattices ----------------------------------------------------------------------------- */

/** The FCC points within `radius` of `centre` (NULL: the origin) at nearest-neighbour distance
 * `spacing`: the cubic grid of step spacing / sqrt 2 through the centre, points with an even
 * index sum, ordered by z, then y, then x index. These are exactly the points, in the same order,
 * that sph_world_fill_sphere makes for a float centre, radius and spacing (so its particle ids
 * follow this order). *positions (3 floats a point) is malloc'd; the caller frees it. Errors:
 * INVALID_ARGUMENT (spacing not positive, radius negative or above 1e6 spacings; no library
 * message), OUT_OF_HOST_MEMORY. */
sph_result support_fcc_sphere(const double* centre, double radius, double spacing, float** positions,
                              uint32_t* count);

/** FCC points tiling the box [0, layers[0] step) x [0, layers[1] step) x [0, layers[2] step)
 * (+ origin; NULL: the origin) with no gap at the faces: the simple-cubic points
 * (i + 1/2) step with an even index sum, ordered by k, then j, then i. Each point stands for the
 * volume 2 step^3 = spacing^3 / sqrt 2 of the world's FCC lattice at spacing = step sqrt 2, so the
 * box holds exactly its volume at rest density. *positions is malloc'd. Errors:
 * OUT_OF_HOST_MEMORY. */
sph_result support_fcc_box(const uint32_t layers[3], double step, const double* origin, float** positions,
                           uint32_t* count);

/* ---- worlds ----------------------------------------------------------------------------------- */

/** A context with one world, and what the tests read back from it once. */
typedef struct support_world {
  sph_context* context;
  sph_world* world;
  sph_world_def def;       /* as the world reports it: kernel radius and rest density filled in */
  sph_world_params params; /* as last set (the defaults when the opener was given none) */
  float mass;              /* the particle mass */
} support_world;

/** Creates a context on `backend` and a world from `def` (NULL: sph_world_def_init's defaults;
 * its struct_size and header_version are set here, so a def built field by field works), sets
 * `params` (NULL: leaves the world's defaults) and reads back def, params and mass. On failure
 * what was made is left in *w: support_world_close releases it. */
sph_result support_world_open(support_world* w, sph_backend backend, const sph_world_def* def,
                              const sph_world_params* params);
/** Sets w->params on the world (after the caller changed them). */
sph_result support_world_set_params(support_world* w);
/** Destroys the world and the context (either may be NULL) and clears *w. */
sph_result support_world_close(support_world* w);

/** Fills *params with the defaults (sph_world_params_init) but gravity and the step limits
 * [dt_min, dt_max]. */
sph_result support_params_gravity_and_steps(sph_world_params* params, float gx, float gy, float gz,
                                            float dt_min, float dt_max);
/** Sets those parameters on a world. */
sph_result support_set_gravity_and_steps(sph_world* world, float gx, float gy, float gz, float dt_min,
                                         float dt_max);

/* ---- particles in ----------------------------------------------------------------------------- */

/** Spawns `count` particles from packed arrays (3 floats each; velocities NULL: at rest). */
sph_result support_spawn(sph_world* world, const float* positions, const float* velocities, uint32_t count);

/** Spawns `count` particles at `positions` with velocities from
 * support_random_velocities(speed, no drift, state); *kinetic_energy (optional) receives their
 * kinetic energy, the sum over components of m v^2 / 2 in double, in spawn order. Errors: those
 * of the calls, OUT_OF_HOST_MEMORY. */
sph_result support_spawn_disturbed(sph_world* world, const float* positions, uint32_t count, double speed,
                                   uint64_t* state, double* kinetic_energy);

/* ---- particles out ---------------------------------------------------------------------------- */

/** Bytes an attribute takes per particle: 12 for position and velocity, 4 otherwise. */
size_t support_attribute_size(sph_attribute attribute);

/** Copies one attribute of every particle, in the world's storage order, into `out` (room for
 * `max` particles); *count receives the particle count. Errors: those of the calls
 * (BUFFER_TOO_SMALL when the world holds more than max). */
sph_result support_read(const sph_world* world, sph_attribute attribute, void* out, uint32_t max,
                        uint32_t* count);
/** The same, ordered by particle id: the attribute of id k at out + k * size. Needs the ids to
 * be 0 .. count-1 (particles spawned into an empty world, none removed); INVALID_ARGUMENT
 * otherwise (with the last library call's message, ""), and OUT_OF_HOST_MEMORY. */
sph_result support_read_by_id(const sph_world* world, sph_attribute attribute, void* out, uint32_t max,
                              uint32_t* count);
/** support_read / support_read_by_id into a new malloc'd buffer *out (room for count + 1
 * particles, so never NULL on success); the caller frees it. */
sph_result support_copy(const sph_world* world, sph_attribute attribute, void** out, uint32_t* count);
sph_result support_copy_by_id(const sph_world* world, sph_attribute attribute, void** out, uint32_t* count);

/** Kinetic energy of all particles, sum over velocity components in id order of m v^2 / 2, in
 * double (support_read_by_id's conditions). */
sph_result support_kinetic_energy(const sph_world* world, float mass, double* energy);

/* ---- scenes ----------------------------------------------------------------------------------- */

/** The rest sphere (the thesis's figure 8 benchmark, BENCHMARK.md case 1, and the physics and
 * validation tests' ball): an FCC ball (support_fcc_sphere) at rest density, with random
 * velocities. */
typedef struct support_sphere {
  double centre[3];
  double radius;           /* m */
  double spacing;          /* of the lattice, m; 0: the def's particle_spacing (0 there: the default) */
  double speed;            /* each velocity component uniform in [-speed, speed], m/s */
  const float* drift;      /* NULL, or 3 floats added to every velocity */
  uint64_t random_state;   /* support_random's state for the velocities; advanced */
  uint32_t spare_capacity; /* a def with capacity 0 gets the ball's count plus this */
} support_sphere;

/** support_world_open (backend, def, params; a def->capacity of 0 becomes the ball's count plus
 * sphere->spare_capacity, where sph_world_create would read it as its default), then spawns the ball with
 * velocities from support_random_velocities(speed, drift). *count (optional) receives the particle count.
 * Errors: those of the calls, OUT_OF_HOST_MEMORY; on failure *w holds what was made. */
sph_result support_rest_sphere_open(support_world* w, sph_backend backend, const sph_world_def* def,
                                    const sph_world_params* params, support_sphere* sphere, uint32_t* count);

/** A closed tank: a box SDF used as an inverted collider, so that its inside is the fluid's
 * space; the cavity is centre +- half_extents. */
typedef struct support_tank {
  sph_vec3 centre;       /* m */
  sph_vec3 half_extents; /* m */
  float voxel_size;      /* of the SDF grid, m */
  float friction;        /* of the walls (Coulomb); 0: free slip */
} support_tank;

/** Creates the tank's SDF on `context` and its collider in `world`. *sdf receives the asset
 * (the caller destroys it; the collider keeps its own reference; also after a failure), or, with
 * sdf NULL, the asset is released once the collider holds it (a failure before that leaves it
 * unreleased, so that no call overwrites the failing call's message). collider (optional)
 * receives the collider's id. */
sph_result support_tank_create(sph_context* context, sph_world* world, const support_tank* tank,
                               sph_sdf** sdf, sph_collider_id* collider);

/** The tank whose cavity is the box [min, max]: centre (min + max) / 2 and half extents
 * (max - min) / 2 in double, each rounded once to float (the hydrostatic tank, the closed box,
 * the Martin & Moyce dam break). */
sph_result support_tank_between(sph_context* context, sph_world* world, const double min[3],
                                const double max[3], double voxel_size, float friction, sph_sdf** sdf,
                                sph_collider_id* collider);

/** The dam break: a tank (support_tank_create) and a column of water from sph_world_fill_box over
 * [column_min, column_max] at rest (the benchmark's dam break, the extremes' tank, the threads
 * test's worlds, samples/dam_break). *sdf and collider as support_tank_create; *count
 * (optional) receives the particles added. */
sph_result support_dam_break(sph_context* context, sph_world* world, const support_tank* tank,
                             sph_vec3 column_min, sph_vec3 column_max, sph_sdf** sdf,
                             sph_collider_id* collider, uint32_t* count);

/** Water at rest in a closed tank: support_fcc_box's lattice of `layers` at `step` from the origin,
 * in the tank whose cavity is [tank_min, tank_max] (support_tank_between, voxels of step / 2). */
typedef struct support_water_tank {
  uint32_t layers[3];
  double step;        /* m */
  double tank_min[3]; /* m */
  double tank_max[3]; /* m */
  float friction;     /* of the walls (Coulomb); 0: free slip */
} support_water_tank;

/** support_world_open (backend, def, params; a def->capacity of 0 becomes the lattice's count),
 * the tank (*sdf and collider as support_tank_create's), then the lattice spawned at rest.
 * *count (optional) receives the particle count. Errors: those of the calls, OUT_OF_HOST_MEMORY;
 * on failure *w holds what was made. */
sph_result support_water_tank_open(support_world* w, sph_backend backend, const sph_world_def* def,
                                   const sph_world_params* params, const support_water_tank* scene,
                                   sph_sdf** sdf, sph_collider_id* collider, uint32_t* count);
/** The loads tests' collapsing column: 6 x 14 x 8 layers of 1 cm in a tank 16 x 30 x 8 cm, the
 * column against the faces at x = 0, y = 0 and both z (test_collider_loads.c, test_dfsph_loads.c). */
support_water_tank support_collapsing_column(float friction);
/** The probes tests' resting tank: 12 x 24 x 12 layers of 1 cm (12 cm wide, 24 cm deep) in a tank
 * as wide and twice as deep (test_probes.c, test_dfsph_loads.c). */
support_water_tank support_resting_tank(void);

#ifdef __cplusplus
}
#endif

#endif /* SPH_TESTS_SUPPORT_H */
