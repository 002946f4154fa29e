/* SPDX-License-Identifier: MIT */
/* What the mpi tests of the solvers and the scene's sums share (test_mpi_dfsph.c,
 * test_mpi_scene_sums.c): failure counting over the ranks, the column in its tank, stepping a
 * number of substeps, and the distributed world's particles against the undivided world's, bit
 * for bit, by id. Static functions: each test program includes it once. */
#ifndef SPH_TESTS_MPI_COMPARE_H
#define SPH_TESTS_MPI_COMPARE_H

#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph_c.h"
#include "sph_mpi.h"
#include "support.h"

#define SPACING 0.01f
#define KERNEL_RADIUS (1.8f * SPACING)

static int g_rank = 0, g_size = 1, g_failures = 0;

#include "mpi_check.h"

static const support_tank kTank = {{0.2f, 0.1f, 0.03f}, {0.2f, 0.1f, 0.03f}, 0.005f, 0.0f};

static inline void world_def(sph_world_def* def) {
  REQUIRE(sph_world_def_init(def) == SPH_OK, "def init");
  def->features = SPH_FEATURE_NONE;
  def->capacity = 4096;
  def->particle_spacing = SPACING;
  def->kernel_radius = KERNEL_RADIUS;
}

/* Gravity, adaptive steps, at most `substeps` substeps per frame. */
static inline void set_params(sph_world* world, uint32_t substeps) {
  sph_world_params p;
  REQUIRE(support_params_gravity_and_steps(&p, 0.0f, -9.81f, 0.0f, 1e-5f, 1e-3f) == SPH_OK, "params");
  p.max_substeps = substeps;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
}

/* One frame of `substeps` substeps (a long frame that max_substeps ends), collective when
 * distributed; the frame's stats in *stats. */
static inline void step_substeps(sph_world* world, uint32_t substeps, int distributed, sph_stats* stats) {
  sph_result r;
  set_params(world, substeps);
  r = distributed ? sph_mpi_world_step(world, 1.0f) : sph_world_step(world, 1.0f);
  CHECK(r == SPH_INCOMPLETE, "step: %d, expected SPH_INCOMPLETE after %u substeps", (int)r, substeps);
  REQUIRE(sph_stats_init(stats) == SPH_OK, "stats init");
  REQUIRE(sph_world_get_stats(world, stats) == SPH_OK, "stats");
  CHECK(stats->substeps == substeps, "%u substeps, expected %u", stats->substeps, substeps);
}

/* The undivided world (rank 0: the tank and the column [min, max], stirred at up to `stir` m/s)
 * and the distributed one (every rank: the tank, the particles added from rank 0). Returns the
 * particle count on every rank. */
static inline uint32_t make_worlds(sph_context* context, const sph_world_def* def, sph_vec3 min, sph_vec3 max,
                                   float stir, sph_world** single, sph_world** world,
                                   sph_collider_id* single_tank, sph_collider_id* tank) {
  float* positions = NULL;
  float* velocities = NULL;
  uint32_t n = 0;
  *single = NULL;
  if (g_rank == 0) {
    REQUIRE(sph_world_create(context, def, single) == SPH_OK, "single world");
    REQUIRE(support_dam_break(context, *single, &kTank, min, max, NULL, single_tank, &n) == SPH_OK, "dam");
    REQUIRE(support_copy_by_id(*single, SPH_ATTRIBUTE_POSITION, (void**)&positions, &n) == SPH_OK,
            "positions");
    velocities = (float*)calloc(3 * (size_t)n + 3, sizeof(float));
    REQUIRE(velocities != NULL, "calloc");
    if (stir > 0.0f) {
      uint64_t state = 12345;
      support_random_velocities(velocities, n, stir, NULL, &state);
      REQUIRE(
          sph_world_set_attribute(*single, SPH_ATTRIBUTE_VELOCITY, velocities, 12ull * n, 12, 0, n) == SPH_OK,
          "stir");
    }
  }
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  REQUIRE(sph_mpi_world_create(context, def, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD), NULL, world) == SPH_OK,
          "distributed world");
  REQUIRE(support_tank_create(context, *world, &kTank, NULL, tank) == SPH_OK, "tank");
  REQUIRE(sph_mpi_world_add_particles(*world, positions, velocities, g_rank == 0 ? n : 0, NULL) == SPH_OK,
          "add particles");
  free(positions);
  free(velocities);
  return n;
}

static const uint32_t* g_sort_ids; /* support_id_order's key (qsort takes no context) */

static int compare_by_id(const void* a, const void* b) {
  const uint32_t x = g_sort_ids[*(const uint32_t*)a], y = g_sort_ids[*(const uint32_t*)b];
  return x < y ? -1 : (x > y ? 1 : 0);
}

/* The undivided world's ids, positions and velocities in id order (its ids need not be dense:
 * sinks remove some). Returns the count; the caller frees the three arrays. */
static inline uint32_t read_in_id_order(sph_world* single, uint32_t** ids, float** x, float** v) {
  uint32_t n = 0, m = 0;
  uint32_t* id = NULL;
  float* px = NULL;
  float* pv = NULL;
  uint32_t* order;
  REQUIRE(support_copy(single, SPH_ATTRIBUTE_ID, (void**)&id, &n) == SPH_OK, "read ids");
  REQUIRE(support_copy(single, SPH_ATTRIBUTE_POSITION, (void**)&px, &m) == SPH_OK && m == n, "read");
  REQUIRE(support_copy(single, SPH_ATTRIBUTE_VELOCITY, (void**)&pv, &m) == SPH_OK && m == n, "read");
  order = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
  *ids = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
  *x = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
  *v = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
  REQUIRE(order && *ids && *x && *v, "malloc");
  for (uint32_t i = 0; i < n; ++i) order[i] = i;
  g_sort_ids = id;
  qsort(order, n, sizeof(uint32_t), compare_by_id);
  for (uint32_t i = 0; i < n; ++i) {
    (*ids)[i] = id[order[i]];
    memcpy(*x + 3 * (size_t)i, px + 3 * (size_t)order[i], 12);
    memcpy(*v + 3 * (size_t)i, pv + 3 * (size_t)order[i], 12);
  }
  free(order);
  free(id);
  free(px);
  free(pv);
  return n;
}

/* The distributed world's particles (gathered on rank 0, by id) against the undivided world's:
 * the same ids, positions and velocities bit for bit. Collective. */
static inline void expect_same_particles(sph_world* single, sph_world* world, const char* name) {
  sph_mpi_counts counts;
  uint32_t n = 0;
  float* got_x = NULL;
  float* got_v = NULL;
  uint32_t* got_id = NULL;
  uint64_t gathered = 0;
  REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK, "counts init");
  REQUIRE(sph_mpi_world_get_counts(world, &counts) == SPH_OK, "counts");
  if (g_rank == 0) {
    n = (uint32_t)counts.global_count;
    got_x = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    got_v = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    got_id = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
    REQUIRE(got_x && got_v && got_id, "malloc");
  }
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  REQUIRE(sph_mpi_world_gather(world, 0, got_x, got_v, got_id, n, &gathered) == SPH_OK, "gather");
  if (g_rank == 0) {
    float* want_x = NULL;
    float* want_v = NULL;
    uint32_t* want_id = NULL;
    uint32_t differ, common;
    double worst = 0.0;
    const uint32_t m = read_in_id_order(single, &want_id, &want_x, &want_v);
    CHECK(gathered == n && m == n, "%s: gathered %llu, the world holds %u, the undivided world %u", name,
          (unsigned long long)gathered, n, m);
    common = n < m ? n : m;
    if (gathered < common) common = (uint32_t)gathered;
    for (uint32_t i = 0; i < common; ++i)
      CHECK(got_id[i] == want_id[i], "%s: id %u at %u, the undivided world's %u", name, got_id[i], i,
            want_id[i]);
    differ = mpi_differ(got_x, got_v, want_x, want_v, common, &worst);
    CHECK(differ == 0,
          "%s on %d ranks: %u of %u particles differ from the undivided world (worst position %g m)", name,
          g_size, differ, n, worst);
    printf("%s on %d ranks: %u particles, %u differ; %llu ghosts in the last substep, %llu migrations\n",
           name, g_size, n, differ, (unsigned long long)counts.global_ghosts,
           (unsigned long long)counts.migrated);
    free(want_x);
    free(want_v);
    free(want_id);
  }
  free(got_x);
  free(got_v);
  free(got_id);
}

/* The same bytes on every rank. */
static inline int same_on_every_rank(const void* bytes, int size) {
  unsigned char* all = (unsigned char*)malloc((size_t)size * (size_t)g_size);
  int same = 1;
  REQUIRE(all != NULL, "malloc");
  MPI_Allgather(bytes, size, MPI_BYTE, all, size, MPI_BYTE, MPI_COMM_WORLD);
  for (int r = 1; r < g_size; ++r)
    same = same && memcmp(all, all + (size_t)r * (size_t)size, (size_t)size) == 0;
  free(all);
  return same;
}

static inline void mpi_test_begin(int* argc, char*** argv, sph_context** context) {
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  REQUIRE(support_context_create(SPH_BACKEND_CPU, context) == SPH_OK, "context");
}

static inline int mpi_test_end(sph_context* context) {
  int total = 0;
  REQUIRE(sph_context_destroy(context) == SPH_OK, "context destroy");
  MPI_Allreduce(&g_failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (g_rank == 0) printf("%s: %d failures over %d ranks\n", total == 0 ? "PASS" : "FAIL", total, g_size);
  MPI_Finalize();
  return total == 0 ? 0 : 1;
}

#endif
