/* SPDX-License-Identifier: MIT */
/* DFSPH's depth step limit in a distributed world (docs/physics.md, DFSPH, Limits): dt <=
 * f h / sqrt(|g| H), H the fluid's extent along gravity, a min and a max over the particles that
 * every rank reduces over the ranks (cpu_halo.cpp, reduce_step_inputs), so a rank that holds only
 * the top of the column takes the undivided world's step. Scene: a column 6 x 20 x 6 cm at rest in
 * the tests' tank (a DFSPH world, dt_max 50 ms), whose longest axis is its height, so the slabs cut
 * it along gravity (checked: the counters' axis is y); two frames of 20 ms.
 * Checked, under mpirun on 1-3 ranks:
 *   - the limit binds: the undivided world's first frame takes at least five substeps of at most
 *     4.5 ms (0.3 h / sqrt(g H) is about 4 ms at h = 1.8 cm, H about 0.19 m), where dt_max and the
 *     CFL would take the 20 ms frame of still water in one;
 *   - every rank's sph_stats substeps, dt_min and dt_max equal the undivided world's bit for bit,
 *     and the gathered particles equal its particles bit for bit.
 * With the argument `cuda` (not a ctest: CI has no GPU) the same on CUDA ranks against an undivided
 * CUDA world (the height span reduced on the device, its keys over the ranks: cuda_halo_frame.cu):
 * `mpirun --oversubscribe -np 2 build/tests/mpi/mpi_depth_step cuda`. */
#include "mpi_compare.h"

static void set_stepping(sph_world* world, uint32_t dfsph_flags) {
  sph_world_params p;
  sph_dfsph_params d;
  REQUIRE(sph_world_params_init(&p) == SPH_OK && sph_dfsph_params_init(&d) == SPH_OK, "init");
  REQUIRE(sph_world_get_params(world, &p) == SPH_OK, "get params");
  p.dt_min = 1e-5f;
  p.dt_max = 0.05f;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
  REQUIRE(sph_world_get_dfsph_params(world, &d) == SPH_OK, "get dfsph params");
  d.flags = dfsph_flags;
  REQUIRE(sph_world_set_dfsph_params(world, &d) == SPH_OK, "set dfsph params");
}

static void frame(sph_world* world, int distributed, sph_stats* out) {
  sph_stats_init(out);
  REQUIRE((distributed ? sph_mpi_world_step(world, 0.02f) : sph_world_step(world, 0.02f)) == SPH_OK, "step");
  REQUIRE(sph_world_get_stats(world, out) == SPH_OK, "stats");
}

int main(int argc, char** argv) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.06f, 0.2f, 0.06f};
  mpi_test_init(&argc, &argv, &context);
  if (argc > 1 && strcmp(argv[1], "cuda") == 0) {
    REQUIRE(sph_context_destroy(context) == SPH_OK, "context destroy");
    REQUIRE(support_context_create(SPH_BACKEND_CUDA, &context) == SPH_OK, "CUDA context");
  }
  mpi_test_world_def(&def);
  def.solver = SPH_SOLVER_DFSPH;
  (void)make_worlds(context, &def, column_min, column_max, 0.0f, &single, &world, &single_tank, &tank);
  (void)single_tank;
  (void)tank;
  set_stepping(world, 0u);
  if (g_rank == 0) set_stepping(single, 0u);
  for (int f = 0; f < 2; ++f) {
    sph_stats got, want;
    sph_mpi_counts counts;
    uint32_t want_bytes[3] = {0u, 0u, 0u}, got_bytes[3];
    frame(world, 1, &got);
    if (g_rank == 0) {
      frame(single, 0, &want);
      want_bytes[0] = want.substeps;
      memcpy(&want_bytes[1], &want.dt_min, sizeof(float));
      memcpy(&want_bytes[2], &want.dt_max, sizeof(float));
      printf("frame %d: %u substeps, dt %.9g .. %.9g s (undivided)\n", f, want.substeps, (double)want.dt_min,
             (double)want.dt_max);
      /* The first frame: the water at rest, the depth limit alone binds (about 4 ms: five or six
       * steps; dt_max and the CFL at the speeds one frame of fall gives, 0.2 m/s at most, would
       * take the 20 ms frame in one). */
      if (f == 0)
        CHECK(
            want.substeps >= 5 && want.dt_max < 0.0045f,
            "the undivided world's first frame took %u substeps of up to %g s: the depth limit did not bind",
            want.substeps, (double)want.dt_max);
    }
    MPI_Bcast(want_bytes, 3, MPI_UINT32_T, 0, MPI_COMM_WORLD);
    got_bytes[0] = got.substeps;
    memcpy(&got_bytes[1], &got.dt_min, sizeof(float));
    memcpy(&got_bytes[2], &got.dt_max, sizeof(float));
    CHECK(memcmp(got_bytes, want_bytes, sizeof got_bytes) == 0,
          "frame %d, rank %d: %u substeps, dt %.9g .. %.9g; the undivided world's %u", f, g_rank,
          got.substeps, (double)got.dt_min, (double)got.dt_max, want_bytes[0]);
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK, "counts init");
    REQUIRE(sph_mpi_world_get_counts(world, &counts) == SPH_OK, "counts");
    if (g_size > 1)
      CHECK(counts.axis == 1, "the slabs' axis is %d, not y: the column is not split", counts.axis);
  }
  expect_same_particles(single, world, "depth step limit");
  if (single) sph_world_destroy(single);
  sph_world_destroy(world);
  return mpi_test_finish(context, "mpi_depth_step");
}
