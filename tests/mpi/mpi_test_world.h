/* SPDX-License-Identifier: MIT */
/* What the mpi tests of checkpoints, failures and rebalancing share: the ranks, the checks, the
 * dam break of test_mpi_distributed_world.c (a column in a closed tank, gravity) made on every
 * rank from rank 0's particles, stepping by substeps, and gathering onto rank 0. */
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
#define MPI_TEST_COMM ((int32_t)MPI_Comm_c2f(MPI_COMM_WORLD))

void mpi_test_init(int* argc, char*** argv, sph_context** context);
/* Reduces the failures over the ranks, prints PASS or FAIL on rank 0, finalises MPI; the exit code. */
int mpi_test_finish(sph_context* context, const char* name);

void mpi_test_world_def(sph_world_def* def);
/* The column [0, 0.1] x [0, 0.2] x [0, 0.06] in the tank [0, 0.4] x [0, 0.2] x [0, 0.06], stirred
 * with random velocities up to `stir` m/s: *single (rank 0 only, unless single is NULL) the
 * undivided world, *world the distributed one (mpi_def may be NULL); *n the particles. */
void mpi_test_dam(sph_context* context, const sph_world_def* def, float stir,
                  const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n);
/* mpi_test_dam on the ranks of `comm` (rank 0 of it builds the undivided world). */
void mpi_test_dam_on(sph_context* context, const sph_world_def* def, float stir, MPI_Comm comm,
                     const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n);
/* `substeps` substeps in one frame that max_substeps ends (collective when distributed). */
void mpi_test_step(sph_world* world, uint32_t substeps, int distributed);
/* The distributed world's positions and velocities by id on rank 0 (malloc'd; NULL elsewhere). */
void mpi_test_gather(sph_world* world, uint32_t n, float** x, float** v);
/* mpi_test_gather for a world on `comm`: onto its rank 0. */
void mpi_test_gather_on(sph_world* world, MPI_Comm comm, uint32_t n, float** x, float** v);
/* An undivided world's positions and velocities by id (malloc'd). */
void mpi_test_read(sph_world* single, uint32_t n, float** x, float** v);
/* The path of rank `rank`'s file named in the manifest at `manifest` (in its directory; the
 * names carry the file's hash, sph_mpi.h): 1, or 0 if the manifest cannot be read as one. */
int mpi_test_rank_file(const char* manifest, int rank, char* out, size_t size);

#ifdef __cplusplus
}
#endif

#endif
