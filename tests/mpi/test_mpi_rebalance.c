/* SPDX-License-Identifier: MIT */
/* Rebalancing after a column collapses, under mpirun on 1-4 ranks. The dam break's column
 * (0.1 m wide, 0.2 m tall) is first cut into slabs along y, its longest axis; as it collapses
 * and runs along the tank's floor, the upper slabs empty and the ranks that own them fall below
 * the mean until the fullest holds more than 120% of it (the default threshold): the next frame
 * cuts new slabs (along x, once the surge is wider than the column is tall). Frames of
 * FRAME_SUBSTEPS substeps until FRAMES frames; then:
 *   - on 2-4 ranks the slabs were cut again after the first frame (rebalances >= 2);
 *   - the particle count is the world's and each id 0 .. n-1 is held once (count and mass, n
 *     times the particle mass, conserved through the migrations and the new cuts);
 *   - the gathered particles equal the undivided world's bit for bit (the sort keys keep every
 *     sum in the undivided world's order across the new cuts, as in test_mpi_distributed_world.c:
 *     no tolerance).
 * First, the first cut's balance (check_first_cut): a still lattice of 48 planes of 25 particles
 * along y, planes 0.01 m apart against layers of 0.018 m, so that a layer holds one or two
 * planes: cut between sub-layers (a sixteenth of a layer, src/core/slab_rules.h) the slabs split
 * the world between planes, each rank holding exactly the planes up to the one where its running
 * target ceil(r n / R) is reached (on 2 and 4 ranks 600 / 300 particles each; whole layers gave
 * 625 + 575 and 325 + 300 + 275 + 300), and each rank holds exactly the particles whose
 * sub-layer its slab_sub_first .. slab_sub_last names. */
#include <stdlib.h>
#include <string.h>

#include "mpi_test_world.h"
#include "support.h"

#define FRAME_SUBSTEPS 20
#define FRAMES 12

#define LATTICE_PLANES 48
#define LATTICE_SIDE 5

static void check_first_cut(sph_context* context) {
  const uint32_t plane = LATTICE_SIDE * LATTICE_SIDE, n = LATTICE_PLANES * plane;
  /* The planes sit a sixteenth's 1/18 (62.5 um) from every sub-layer boundary: one substep of
   * 1e-5 s moves none across one. */
  const float y0 = MPI_TEST_KERNEL_RADIUS * (4.0f + 1.0f / 18.0f) / 16.0f;
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_params p;
  sph_mpi_counts counts;
  float* positions = (float*)malloc(sizeof(float) * 3 * n);
  float *x = NULL, *v = NULL;
  int32_t mine[3], *all = (int32_t*)malloc(sizeof(int32_t) * 3 * (size_t)g_size);
  REQUIRE(positions && all, "malloc");
  for (uint32_t k = 0, i = 0; k < LATTICE_PLANES; ++k)
    for (uint32_t a = 0; a < LATTICE_SIDE; ++a)
      for (uint32_t b = 0; b < LATTICE_SIDE; ++b, ++i) {
        positions[3 * i] = 0.005f + MPI_TEST_SPACING * (float)a;
        positions[3 * i + 1] = y0 + MPI_TEST_SPACING * (float)k;
        positions[3 * i + 2] = 0.005f + MPI_TEST_SPACING * (float)b;
      }
  mpi_test_world_def(&def);
  REQUIRE(sph_mpi_world_create(context, &def, MPI_TEST_COMM, NULL, &world) == SPH_OK, "lattice world");
  REQUIRE(sph_mpi_world_add_particles(world, positions, NULL, g_rank == 0 ? n : 0, NULL) == SPH_OK,
          "lattice");
  REQUIRE(support_params_gravity_and_steps(&p, 0.0f, 0.0f, 0.0f, 1e-5f, 1e-5f) == SPH_OK, "params");
  p.max_substeps = 1;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
  REQUIRE(sph_mpi_world_step(world, 1.0f) == SPH_INCOMPLETE, "one substep");
  REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK && sph_mpi_world_get_counts(world, &counts) == SPH_OK,
          "counts");
  mine[0] = (int32_t)counts.local_count;
  mine[1] = counts.slab_sub_first;
  mine[2] = counts.slab_sub_last;
  MPI_Gather(mine, 3, MPI_INT32_T, all, 3, MPI_INT32_T, 0, MPI_COMM_WORLD);
  mpi_test_gather(world, n, &x, &v);
  if (g_rank == 0) {
    uint64_t reached = 0;
    for (int r = 0; r < g_size; ++r) {
      /* The planes up to the one where ceil(r n / R) is reached. */
      const uint64_t target = ((uint64_t)n * (uint64_t)(r + 1) + (uint64_t)g_size - 1) / (uint64_t)g_size;
      const uint64_t through = (target + plane - 1) / plane * plane;
      const int32_t held = all[3 * r], first = all[3 * r + 1], last = all[3 * r + 2];
      uint32_t owned = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const int32_t sub = mpi_test_sub_layer(x[3 * i + 1]);
        owned += sub >= first && sub <= last ? 1u : 0u;
      }
      CHECK(
          (uint64_t)held == through - reached,
          "first cut on %d ranks: rank %d holds %d particles, expected %llu (the planes up to the one where "
          "its target %llu is reached)",
          g_size, r, held, (unsigned long long)(through - reached), (unsigned long long)target);
      CHECK(owned == (uint32_t)held, "rank %d holds %d particles, its sub-layers %d..%d %u", r, held, first,
            last, owned);
      reached = through;
    }
    printf("first cut on %d ranks: %u particles in planes of %u; rank 0 holds %d\n", g_size, n, plane,
           all[0]);
  }
  free(positions);
  free(all);
  free(x);
  free(v);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
}

int main(int argc, char** argv) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_mpi_counts counts;
  uint32_t n = 0, first_cut_frame = 0, recut_frame = 0;
  int32_t axis0 = -1;
  float *x = NULL, *v = NULL, *want_x = NULL, *want_v = NULL;
  uint32_t* ids = NULL;
  uint64_t got = 0;
  mpi_test_init(&argc, &argv, &context);
  check_first_cut(context);
  mpi_test_world_def(&def);
  def.particle_spacing = 0.0125f; /* 640 particles: the collapse in a few seconds of CPU on 4 ranks */
  def.kernel_radius = 1.8f * 0.0125f;
  mpi_test_dam(context, &def, 0.0f, NULL, &single, &world, &n);
  for (uint32_t frame = 0; frame < FRAMES; ++frame) {
    if (g_rank == 0) mpi_test_step(single, FRAME_SUBSTEPS, 0);
    mpi_test_step(world, FRAME_SUBSTEPS, 1);
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK && sph_mpi_world_get_counts(world, &counts) == SPH_OK,
            "counts");
    if (frame == 0) {
      axis0 = counts.axis;
      first_cut_frame = counts.rebalances;
    }
    if (!recut_frame && counts.rebalances >= 2) recut_frame = frame + 1;
  }
  CHECK(first_cut_frame == 1, "%u cuts in the first frame", first_cut_frame);
  CHECK(axis0 == 1 || g_size == 1, "the first cut along axis %d, expected y (1)", axis0);
  CHECK(g_size == 1 || counts.rebalances >= 2,
        "%u rebalances on %d ranks after %u substeps: the collapse did "
        "not unbalance the slabs",
        counts.rebalances, g_size, FRAMES * FRAME_SUBSTEPS);
  CHECK(g_size > 1 || counts.rebalances == 1, "%u rebalances on one rank", counts.rebalances);
  CHECK(g_size == 1 || counts.axis == 0,
        "the slabs along axis %d at the end, expected x (0): the surge is wider than the column is tall",
        counts.axis);
  CHECK(counts.global_count == n, "%llu particles, %u added", (unsigned long long)counts.global_count, n);
  if (g_rank == 0) {
    x = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    v = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    ids = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
    REQUIRE(x && v && ids, "malloc");
  }
  REQUIRE(sph_mpi_world_gather(world, 0, x, v, ids, n, &got) == SPH_OK, "gather");
  if (g_rank == 0) {
    uint32_t differ;
    CHECK(got == n, "gathered %llu of %u", (unsigned long long)got, n);
    for (uint32_t i = 0; i < n; ++i) CHECK(ids[i] == i, "id %u at %u: each id once", ids[i], i);
    mpi_test_read(single, n, &want_x, &want_v);
    differ = mpi_differ(x, v, want_x, want_v, n, NULL);
    CHECK(differ == 0, "on %d ranks after %u substeps: %u of %u particles differ from the undivided world",
          g_size, FRAMES * FRAME_SUBSTEPS, differ, n);
    printf(
        "column collapse on %d ranks: %u particles, %u substeps, %u rebalances (the second in frame %u, "
        "axis %d then %d), %llu migrations, %u differ from the undivided world\n",
        g_size, n, FRAMES * FRAME_SUBSTEPS, counts.rebalances, recut_frame, axis0, counts.axis,
        (unsigned long long)counts.migrated, differ);
  }
  free(x);
  free(v);
  free(ids);
  free(want_x);
  free(want_v);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
  return mpi_test_finish(context, "mpi rebalance");
}
