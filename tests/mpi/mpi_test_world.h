/* SPDX-License-Identifier: MIT */
/* What the mpi tests share: the ranks, the checks, the dam break (a column in a closed tank,
 * gravity) built twice, undivided on rank 0 and distributed over the ranks from rank 0's
 * particles, stepping by substeps, and gathering onto rank 0. */
#ifndef SPH_MPI_TEST_WORLD_H
#define SPH_MPI_TEST_WORLD_H

#include <mpi.h>
#include <stdint.h>
#include <stdio.h>

#include "sph_c.h"
#include "sph_mpi.h"

#ifdef __cplusplus
extern "C" {
#endif

extern int g_rank, g_size, g_failures;

#include "mpi_check.h"

#define MPI_TEST_SPACING 0.01f
#define MPI_TEST_KERNEL_RADIUS (1.8f * MPI_TEST_SPACING)
#define MPI_TEST_COMM ((int32_t)MPI_Comm_c2f(MPI_COMM_WORLD))

void mpi_test_init(int* argc, char*** argv, sph_context** context);
/* Reduces the failures over the ranks, prints PASS or FAIL on rank 0, finalises MPI; the exit code. */
int mpi_test_finish(sph_context* context, const char* name);

/* No features, capacity 4096, spacing MPI_TEST_SPACING, kernel radius MPI_TEST_KERNEL_RADIUS. */
void mpi_test_world_def(sph_world_def* def);

/* A CUDA context (the GPU check programs) with `lanes` threads a particle (0: the library's choice)
 * and the DFSPH walk SPH_TEST_CUDA_DFSPH_MASKS names (sph_test_cuda_dfsph_masks); aborts the job if
 * it cannot be made. */
sph_context* mpi_test_cuda_context(uint32_t lanes);

/* The dam break's two worlds. */
typedef struct mpi_test_worlds {
  sph_world* single;           /* rank 0 of the communicator: the undivided world; NULL elsewhere */
  sph_world* world;            /* the distributed world */
  sph_collider_id single_tank; /* rank 0: the undivided world's tank */
  sph_collider_id tank;        /* the distributed world's tank */
  uint32_t n;                  /* the particles, on every rank */
  uint32_t first;              /* the first id sph_mpi_world_add_particles gave on this rank */
} mpi_test_worlds;

/* The column [column_min, column_max] (sph_world_fill_box) in the tank [0, 0.4] x [0, 0.2] x
 * [0, 0.06], stirred with random velocities up to `stir` m/s (support_random_velocities, seed
 * 12345; 0: at rest): rank 0 of `comm` builds the undivided world, every rank of it the
 * distributed one (mpi_def may be NULL) with the same tank and rank 0's particles, by id. */
void mpi_test_make_worlds(sph_context* context, const sph_world_def* def, sph_vec3 column_min,
                          sph_vec3 column_max, float stir, MPI_Comm comm, const sph_mpi_world_def* mpi_def,
                          mpi_test_worlds* out);
/* mpi_test_make_worlds with the column [0, 0.1] x [0, 0.2] x [0, 0.06]: *single (rank 0 only,
 * unless single is NULL) the undivided world, *world the distributed one; *n the particles. */
void mpi_test_dam(sph_context* context, const sph_world_def* def, float stir,
                  const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n);
/* mpi_test_dam on the ranks of `comm` (rank 0 of it builds the undivided world). */
void mpi_test_dam_on(sph_context* context, const sph_world_def* def, float stir, MPI_Comm comm,
                     const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n);
/* `substeps` substeps in one frame that max_substeps ends (collective when distributed), gravity
 * and adaptive steps in [1e-5, 1e-3] s. */
void mpi_test_step(sph_world* world, uint32_t substeps, int distributed);
/* mpi_test_step, the frame's stats in *stats. */
void mpi_test_step_stats(sph_world* world, uint32_t substeps, int distributed, sph_stats* stats);
/* Whether every rank holds the same solver statistics, bit for bit: every field of `stats` that
 * the DFSPH solves write (pressure_iterations through divergence_solves_capped, and
 * density_error_largest), by an all-reduce of each field's minimum and maximum over MPI_COMM_WORLD
 * (a float by its bits). Collective. NULL when they agree on every field, else the name of the
 * first field that differs (the same answer on every rank). */
const char* mpi_test_solver_stats_differ(const sph_stats* stats);
/* The distributed world's positions and velocities by id on rank 0 (malloc'd; NULL elsewhere). */
void mpi_test_gather(sph_world* world, uint32_t n, float** x, float** v);
/* mpi_test_gather for a world on `comm`: onto its rank 0. */
void mpi_test_gather_on(sph_world* world, MPI_Comm comm, uint32_t n, float** x, float** v);
/* The sub-layer of coordinate x along the slabs' axis (src/core/slab_rules.h; sph_mpi_counts'
 * slab_sub_first/last): 16 times its cell layer floor(x / MPI_TEST_KERNEL_RADIUS), plus the
 * sixteenth of that layer it lies in. */
int32_t mpi_test_sub_layer(float x);
/* An undivided world's positions and velocities by id (malloc'd). */
void mpi_test_read(sph_world* single, uint32_t n, float** x, float** v);
/* A point probe at (0.05, 0.02, 0.03) m and a gauge 0.25 m long from (0.031, -0.01, 0.027) m against
 * gravity, both sampled every substep (the stirred column's probes). */
void mpi_test_add_probes(sph_world* world, sph_probe_id* point, sph_probe_id* gauge);
/* A sink removing every particle outside [-1, 1] x [-1, 0.185] x [-1, 1] m: the stirred column's
 * top, where splashes go. */
void mpi_test_add_top_sink(sph_world* world);
/* A block [lo, hi] filled into the undivided world `single` (on rank 0) and added to the
 * distributed `world` by rank `adder` alone, with the same positions; *n grows by the block's
 * count on every rank. */
void mpi_test_add_block(sph_world* single, sph_world* world, sph_vec3 lo, sph_vec3 hi, int adder,
                        uint32_t* n);
/* The last step's removed ids (malloc'd, *count of them) and its SPH_EVENT_SINK_REMOVED count. */
uint32_t* mpi_test_removed_ids(sph_world* world, uint32_t* count, uint32_t* event_count);
/* The path of rank `rank`'s file named in the manifest at `manifest` (in its directory; the
 * names carry the file's hash, sph_mpi.h): 1, or 0 if the manifest cannot be read as one. */
int mpi_test_rank_file(const char* manifest, int rank, char* out, size_t size);

#ifdef __cplusplus
}
#endif

#endif
