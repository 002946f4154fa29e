/* SPDX-License-Identifier: MIT */
/* What the mpi tests of the solvers, the scene's sums and the sources share (test_mpi_solvers.c,
 * test_mpi_scene_sums.c, test_mpi_sources.c), beyond mpi_test_world.h (the ranks, the column in
 * its tank, stepping a number of substeps): the distributed world's particles against the
 * undivided world's, bit for bit, by id (the undivided world's ids need not be dense). Static
 * functions: each test program includes it once. */
#ifndef SPH_TESTS_MPI_COMPARE_H
#define SPH_TESTS_MPI_COMPARE_H

#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_test_world.h"
#include "sph_c.h"
#include "sph_mpi.h"
#include "support.h"

/* The undivided world (rank 0: the tank and the column [min, max], stirred at up to `stir` m/s)
 * and the distributed one on every rank (mpi_test_make_worlds on MPI_COMM_WORLD). Returns the
 * particle count on every rank. */
static inline uint32_t make_worlds(sph_context* context, const sph_world_def* def, sph_vec3 min, sph_vec3 max,
                                   float stir, sph_world** single, sph_world** world,
                                   sph_collider_id* single_tank, sph_collider_id* tank) {
  mpi_test_worlds w;
  mpi_test_make_worlds(context, def, min, max, stir, MPI_COMM_WORLD, NULL, &w);
  *single = w.single;
  *world = w.world;
  *single_tank = w.single_tank;
  *tank = w.tank;
  return w.n;
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

#endif
