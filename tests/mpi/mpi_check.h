/* SPDX-License-Identifier: MIT */
/* The mpi tests' checks: CHECK counts a failure on this rank and goes on (the ranks add their
 * counts at the end, so every rank still makes every collective call); REQUIRE aborts the job
 * (for what the rest of the test cannot run without). The including file provides g_rank and
 * g_failures. */
#ifndef SPH_TESTS_MPI_CHECK_H
#define SPH_TESTS_MPI_CHECK_H

#include <mpi.h>
#include <stdio.h>

#include "sph_c.h"

#define CHECK(cond, ...)                                               \
  do {                                                                 \
    if (!(cond)) {                                                     \
      fprintf(stderr, "rank %d: %s:%d: ", g_rank, __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                                    \
      fprintf(stderr, " (last error: %s)\n", sph_get_last_error());    \
      ++g_failures;                                                    \
    }                                                                  \
  } while (0)

#define REQUIRE(cond, ...)          \
  do {                              \
    if (!(cond)) {                  \
      CHECK(cond, __VA_ARGS__);     \
      MPI_Abort(MPI_COMM_WORLD, 1); \
    }                               \
  } while (0)

#endif
