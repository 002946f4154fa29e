// SPDX-License-Identifier: MIT
/* What the C-API tests share: result/message expectations, a populated world fixture and a
 * snapshot that proves a failed call left the world unchanged. */
#ifndef SPH_CAPI_TEST_H
#define SPH_CAPI_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sph_c.h"
#include "support.h"

/* The call returns `expected` and sph_get_last_error() contains `name` (the argument). */
#define EXPECT_ERROR(expected, name, call) \
  capi_expect_error((call), (expected), (name), #call, __FILE__, __LINE__)
/* The same, reporting the given line (for helpers that check on behalf of their caller). */
#define EXPECT_ERROR_AT(line, expected, name, call) \
  capi_expect_error((call), (expected), (name), #call, __FILE__, (line))
/* The call returns SPH_OK and sph_get_last_error() is "". */
#define EXPECT_OK(call) capi_expect_error((call), SPH_OK, NULL, #call, __FILE__, __LINE__)

void capi_expect_error(sph_result got, sph_result expected, const char* name, const char* call,
                       const char* file, int line);

/* Writes a float (NaN, Inf, ...) into a struct at a byte offset. */
void capi_set_float(void* object, size_t offset, float value);

/* The non-finite values every float field is tried with. */
#define CAPI_NON_FINITE_COUNT 3
float capi_non_finite(int i);

/* ---- a world with particles, non-default params and one step behind it ------------------- */
#define CAPI_FIXTURE_CAPACITY 256u
typedef struct capi_fixture {
  sph_context* context;
  sph_world* world;
  sph_world_params params; /* the non-default params the fixture set */
} capi_fixture;

/* cmocka group/test setup and teardown: *state becomes a capi_fixture*. */
int capi_fixture_setup(void** state);
int capi_fixture_teardown(void** state);

/* ---- "the world is unchanged" -------------------------------------------------------------- */
#define CAPI_SNAPSHOT_MAX 512u
typedef struct capi_snapshot {
  uint32_t count;
  sph_world_def def;
  sph_world_params params;
  double simulated_time;
  float positions[3 * CAPI_SNAPSHOT_MAX];
  float velocities[3 * CAPI_SNAPSHOT_MAX];
  float densities[CAPI_SNAPSHOT_MAX];
  uint32_t ids[CAPI_SNAPSHOT_MAX];
} capi_snapshot;

void capi_snapshot_take(const sph_world* world, capi_snapshot* out);
#define EXPECT_UNCHANGED(world, snapshot) capi_expect_unchanged((world), (snapshot), __FILE__, __LINE__)
#define EXPECT_UNCHANGED_AT(line, world, snapshot) \
  capi_expect_unchanged((world), (snapshot), __FILE__, (line))
void capi_expect_unchanged(const sph_world* world, const capi_snapshot* before, const char* file, int line);

/* ---- copies and bitwise comparisons ------------------------------------------------------- */
/* The world's checkpoint in memory (malloc'd: the caller frees it); *size its bytes. */
unsigned char* capi_save(const sph_world* world, uint64_t* size);
/* A copy of the world through its checkpoint (save, then load on `context`). */
sph_world* capi_world_copy(sph_context* context, const sph_world* world);
/* The same particle count and every attribute up to the ids bit for bit (the user attribute is
 * left out: it needs SPH_FEATURE_USER_ATTRIBUTE). */
void capi_expect_same_particles(const sph_world* a, const sph_world* b);

/* ---- loads ------------------------------------------------------------------------------------ */
/* A collider's loads of the last step (sph_collider_get_loads, checked). */
sph_collider_loads capi_loads_of(const sph_world* world, sph_collider_id id);
/* The fluid's momentum, sum m v over the particles of mass `mass`, in double. */
void capi_fluid_momentum(const sph_world* world, float mass, double p[3]);

/* ---- DFSPH ------------------------------------------------------------------------------------ */
/* Sets the world's sph_dfsph_params.flags, its other DFSPH parameters kept (checked). */
void capi_set_dfsph_flags(sph_world* world, uint32_t flags);

/* ---- the log callback's warning -------------------------------------------------------------- */
/* A world on `context` of `features` (64 particles, 2 cm spacing: lattice step 1.414 cm) and an
 * SDF of `shape` (half extents 10 cm) at `voxel` m. With SPH_FEATURE_BOUNDARY_DENSITY, a box and
 * a voxel of 1 cm (coarser than half the step) a collider of it is made and logs a warning
 * (docs/api.md, log_fn); capi_coarse_collider_case makes that one. capi_add_collider adds a
 * collider of `sdf`. */
void capi_collider_case(sph_context* context, uint32_t features, sph_shape shape, float voxel,
                        sph_world** world, sph_sdf** sdf);
void capi_coarse_collider_case(sph_context* context, sph_world** world, sph_sdf** sdf);
sph_result capi_add_collider(sph_world* world, sph_sdf* sdf);

/* ---- running some of a file's cases ---------------------------------------------------------- */
/* Runs the cases of `tests` named in argv[1..] in that order, or all of them without names (a
 * ctest per group of cases, e.g. so that the sanitizer stage can leave out the long settling
 * runs). An unknown name, or more names than cases, prints why and returns 2. */
int capi_run_named_cases(const char* group, const struct CMUnitTest* tests, size_t count, int argc,
                         char** argv);

#endif /* SPH_CAPI_TEST_H */
