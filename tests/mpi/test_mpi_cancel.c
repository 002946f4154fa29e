/* SPDX-License-Identifier: MIT */
/* A cancel requested on one rank while no step runs (sph_world_cancel_step) stops the next step
 * on every rank before its first substep, under mpirun on 1-4 ranks: each rank returns
 * SPH_INCOMPLETE with 0 substeps and its particles unchanged. (Before, the cancelling rank
 * returned alone and the others waited in the frame's first collective call for ever.) The step
 * after it then runs on every rank, and the world still equals the undivided one bit for bit. */
#include <stdlib.h>

#include "mpi_test_world.h"
#include "support.h"

#define SUBSTEPS 5

int main(int argc, char** argv) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_stats stats;
  uint32_t n = 0;
  float *x0 = NULL, *v0 = NULL, *x1 = NULL, *v1 = NULL, *x2 = NULL, *v2 = NULL, *want_x = NULL,
        *want_v = NULL;
  sph_result r;
  mpi_test_init(&argc, &argv, &context);
  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 0.0f, NULL, &single, &world, &n);
  if (g_rank == 0) mpi_test_step(single, SUBSTEPS, 0);
  mpi_test_step(world, SUBSTEPS, 1);
  mpi_test_gather(world, n, &x0, &v0);

  /* The last rank alone asks for the cancel. */
  if (g_rank == g_size - 1) REQUIRE(sph_world_cancel_step(world) == SPH_OK, "cancel");
  r = sph_world_step(world, 0.01f);
  CHECK(r == SPH_INCOMPLETE, "the step after a cancel on rank %d returned %s", g_size - 1,
        sph_result_string(r));
  REQUIRE(sph_stats_init(&stats) == SPH_OK && sph_world_get_stats(world, &stats) == SPH_OK, "stats");
  CHECK(stats.substeps == 0, "the cancelled step ran %u substeps", stats.substeps);
  mpi_test_gather(world, n, &x1, &v1);
  if (g_rank == 0) {
    const uint32_t differ = mpi_differ(x0, v0, x1, v1, n, NULL);
    CHECK(differ == 0, "the cancelled step changed %u of %u particles", differ, n);
  }

  /* The request was used up: the next step runs on every rank. */
  if (g_rank == 0) mpi_test_step(single, SUBSTEPS, 0);
  mpi_test_step(world, SUBSTEPS, 1);
  REQUIRE(sph_world_get_stats(world, &stats) == SPH_OK, "stats");
  CHECK(stats.substeps == SUBSTEPS, "the step after the cancelled one ran %u substeps", stats.substeps);
  mpi_test_gather(world, n, &x2, &v2);
  if (g_rank == 0) {
    uint32_t differ;
    mpi_test_read(single, n, &want_x, &want_v);
    differ = mpi_differ(x2, v2, want_x, want_v, n, NULL);
    CHECK(differ == 0, "on %d ranks: %u of %u particles differ from the undivided world", g_size, differ, n);
    printf(
        "cancel on rank %d of %d: every rank stopped before the first substep; %u particles equal the "
        "undivided world after the next step\n",
        g_size - 1, g_size, n);
  }
  free(x0), free(v0), free(x1), free(v1), free(x2), free(v2), free(want_x), free(want_v);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
  return mpi_test_finish(context, "mpi cancel");
}
