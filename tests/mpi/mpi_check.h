/* SPDX-License-Identifier: MIT */
/* The mpi tests' checks: CHECK counts a failure on this rank and goes on (the ranks add their
 * counts at the end, so every rank still makes every collective call); REQUIRE aborts the job
 * (for what the rest of the test cannot run without). The including file provides g_rank and
 * g_failures. */
#ifndef SPH_TESTS_MPI_CHECK_H
#define SPH_TESTS_MPI_CHECK_H

#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

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

/* How many of n particles differ in any bit of position or velocity (x, v: 3 floats each); with
 * `worst`, the largest position difference of those that differ, in m. */
static inline uint32_t mpi_differ(const float* x0, const float* v0, const float* x1, const float* v1,
                                  uint32_t n, double* worst) {
  uint32_t differ = 0;
  if (worst) *worst = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    if (memcmp(x0 + 3 * i, x1 + 3 * i, 12) == 0 && memcmp(v0 + 3 * i, v1 + 3 * i, 12) == 0) continue;
    ++differ;
    for (int k = 0; worst && k < 3; ++k) {
      const double d = fabs((double)x0[3 * i + k] - x1[3 * i + k]);
      if (d > *worst) *worst = d;
    }
  }
  return differ;
}

#endif
