/* SPDX-License-Identifier: MIT */
/* Sources and sinks in a distributed world (docs/distributed.md) against one undivided world,
 * under mpirun on 1-4 ranks: the column in its tank, a continuous source beside it whose region
 * spans the column's height (y, the slabs' axis: its lattice points fall in every rank's slab),
 * at most 400 particles a frame, and a sink that removes what lies above y = 0.185 m (the tops of
 * the column and of the source's region, which the source refills at the next frame). Five frames
 * of 3 substeps. Checked after each frame:
 *   - every rank holds the world's count: the ranks decided the same emission (a lattice point
 *     is clear when it is clear of every rank's particles) and each kept its own slab's points;
 *   - the gathered particles are the undivided world's bit for bit, by id, each id once: the
 *     emitted particles got the undivided world's ids;
 *   - where there are several ranks, more than one holds emitted particles;
 *   - the sink: the ranks' removed ids (per rank) together are the undivided world's, as
 *     sph_mpi_world_gather_removed_ids gives them on one rank, and their SPH_EVENT_SINK_REMOVED
 *     counts add up to its count.
 * Then the capacity limit (run_capacity_limit). */
#include "mpi_compare.h"

static int compare_ids(const void* a, const void* b) {
  const uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

static void add_source_and_sink(sph_context* context, sph_world* w) {
  sph_shape_desc shape;
  sph_sdf* box = NULL;
  sph_source_def source;
  sph_source_id source_id;
  REQUIRE(sph_shape_desc_init(&shape) == SPH_OK, "shape init");
  shape.half_extents.x = 0.03f;
  shape.half_extents.y = 0.095f;
  shape.half_extents.z = 0.025f;
  shape.voxel_size = 0.005f;
  REQUIRE(sph_sdf_create_shape(context, &shape, &box) == SPH_OK, "box");
  REQUIRE(sph_source_def_init(&source) == SPH_OK, "source init");
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.region = box;
  source.transform = sph_transform_identity();
  source.transform.position.x = 0.14f;
  source.transform.position.y = 0.1f;
  source.transform.position.z = 0.03f;
  source.rate = 400.0f;
  source.velocity.x = -0.5f;
  REQUIRE(sph_source_create(w, &source, &source_id) == SPH_OK, "source");
  sph_sdf_destroy(box);
  mpi_test_add_top_sink(w);
}

/* The particles SPH_EVENT_SOURCE_CAPACITY_REACHED says the last step did not emit. */
static uint32_t not_emitted(sph_world* w) {
  sph_event events[8];
  uint32_t n = 0, missing = 0;
  REQUIRE(sph_world_get_events(w, events, 8, &n) == SPH_OK, "events");
  for (uint32_t i = 0; i < n && i < 8; ++i)
    if (events[i].type == SPH_EVENT_SOURCE_CAPACITY_REACHED) missing += events[i].count;
  return missing;
}

/* Fixed worlds of 1700 particles a rank. Before the first frame rank 0 holds the whole column
 * (1404 particles) and owns every cell layer, so the first emission is the undivided world's:
 * 296 of the 400 fit, and the event says 104 did not, on every rank; the particles are the
 * undivided world's. The second frame (the column spread over the ranks, each with its own room)
 * has no undivided twin: every rank reports the same event and the same world. */
static void run_capacity_limit(sph_context* context) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  mpi_test_world_def(&def);
  def.capacity = 1700;
  (void)make_worlds(context, &def, column_min, column_max, 0.0f, &single, &world, &single_tank, &tank);
  add_source_and_sink(context, world);
  if (single) add_source_and_sink(context, single);
  for (int f = 0; f < 2; ++f) {
    sph_stats stats;
    sph_mpi_counts counts;
    uint32_t missing;
    mpi_test_step_stats(world, 3, 1, &stats);
    missing = not_emitted(world);
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK && sph_mpi_world_get_counts(world, &counts) == SPH_OK,
            "counts");
    CHECK(same_on_every_rank(&missing, (int)sizeof missing) &&
              same_on_every_rank(&counts.global_count, (int)sizeof counts.global_count),
          "frame %d: the ranks disagree on the emission (%u not emitted here)", f, missing);
    if (f == 0) {
      if (g_rank == 0) {
        mpi_test_step_stats(single, 3, 0, &stats);
        CHECK(missing == not_emitted(single) && missing > 0,
              "the first frame left %u particles not emitted, the undivided world %u", missing,
              not_emitted(single));
        printf("capacity limit on %d ranks: %u of the first frame's particles did not fit\n", g_size,
               missing);
      }
      expect_same_particles(single, world, "source at its capacity limit, frame 0");
    }
  }
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
}

int main(int argc, char** argv) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  uint32_t removed_total = 0, column_count = 0;
  mpi_test_init(&argc, &argv, &context);
  mpi_test_world_def(&def);
  column_count =
      make_worlds(context, &def, column_min, column_max, 0.0f, &single, &world, &single_tank, &tank);
  add_source_and_sink(context, world);
  if (single) add_source_and_sink(context, single);
  for (int f = 0; f < 5; ++f) {
    sph_stats stats;
    sph_mpi_counts counts;
    uint32_t mine = 0, mine_events = 0, want_n = 0;
    uint32_t* mine_ids;
    int* sizes = (int*)malloc(sizeof(int) * (size_t)g_size);
    int* offsets = (int*)malloc(sizeof(int) * (size_t)g_size);
    uint32_t* all_ids = NULL;
    uint32_t* gathered = NULL;
    uint32_t gathered_n = 0;
    int total = 0;
    char name[64];
    REQUIRE(sizes && offsets, "malloc");
    mpi_test_step_stats(world, 3, 1, &stats);
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK && sph_mpi_world_get_counts(world, &counts) == SPH_OK,
            "counts");
    mine_ids = mpi_test_removed_ids(world, &mine, &mine_events);
    MPI_Gather(&mine, 1, MPI_INT, sizes, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (g_rank == 0)
      for (int r = 0; r < g_size; ++r) {
        offsets[r] = total;
        total += sizes[r];
      }
    all_ids = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)total + 1));
    REQUIRE(all_ids != NULL, "malloc");
    MPI_Gatherv(mine_ids, (int)mine, MPI_UINT32_T, all_ids, sizes, offsets, MPI_UINT32_T, 0, MPI_COMM_WORLD);
    {
      uint32_t events_sum = 0;
      MPI_Reduce(&mine_events, &events_sum, 1, MPI_UINT32_T, MPI_SUM, 0, MPI_COMM_WORLD);
      mine_events = events_sum;
    }
    {
      /* The library's gather: on rank 0 the ids of every rank, ascending; on the last rank, with
       * no room, the count alone (SPH_INCOMPLETE on every rank when there are any). */
      uint32_t world_removed = mine, on_last = 99;
      sph_result r;
      gathered = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)total + 1));
      REQUIRE(gathered != NULL, "malloc");
      r = sph_mpi_world_gather_removed_ids(world, 0, g_rank == 0 ? gathered : NULL,
                                           g_rank == 0 ? (uint32_t)total : 0u,
                                           g_rank == 0 ? &gathered_n : NULL);
      CHECK(r == SPH_OK, "gather removed ids: %d", (int)r);
      MPI_Allreduce(MPI_IN_PLACE, &world_removed, 1, MPI_UINT32_T, MPI_SUM, MPI_COMM_WORLD);
      r = sph_mpi_world_gather_removed_ids(world, g_size - 1, NULL, 0, &on_last);
      CHECK(g_rank != g_size - 1 || on_last == world_removed,
            "the count alone on the last rank: %u, expected %u", on_last, world_removed);
      /* SPH_INCOMPLETE on every rank, so that every rank calls again (collectively). */
      CHECK(r == (world_removed > 0 ? SPH_INCOMPLETE : SPH_OK),
            "a gather onto no room: %d on rank %d, expected %d (%u removed)", (int)r, g_rank,
            (int)(world_removed > 0 ? SPH_INCOMPLETE : SPH_OK), world_removed);
      CHECK(sph_mpi_world_gather_removed_ids(world, g_size, NULL, 0, &on_last) == SPH_ERROR_INVALID_ARGUMENT,
            "a root outside the communicator");
    }
    if (g_rank == 0) {
      uint32_t want_events = 0;
      uint32_t* want_ids;
      mpi_test_step_stats(single, 3, 0, &stats);
      want_ids = mpi_test_removed_ids(single, &want_n, &want_events);
      qsort(want_ids, want_n, sizeof(uint32_t), compare_ids);
      qsort(all_ids, (size_t)total, sizeof(uint32_t), compare_ids);
      CHECK((uint32_t)total == want_n && memcmp(all_ids, want_ids, sizeof(uint32_t) * want_n) == 0,
            "frame %d: the ranks removed %d ids, the undivided world %u (or other ids)", f, total, want_n);
      CHECK(gathered_n == want_n && memcmp(gathered, want_ids, sizeof(uint32_t) * want_n) == 0,
            "frame %d: sph_mpi_world_gather_removed_ids gave %u ids, the undivided world %u (or other ids)",
            f, gathered_n, want_n);
      CHECK(mine_events == want_events, "frame %d: sink events count %u, the undivided world %u", f,
            mine_events, want_events);
      removed_total += want_n;
      REQUIRE(sph_world_get_stats(single, &stats) == SPH_OK, "stats");
      CHECK(counts.global_count == stats.particle_count, "frame %d: %llu particles, the undivided world %u",
            f, (unsigned long long)counts.global_count, stats.particle_count);
      free(want_ids);
    }
    {
      /* The emitted particles (ids from the column's count on) this rank holds, per rank. */
      uint32_t* ids = NULL;
      uint32_t local = 0, emitted = 0, holders = 0;
      REQUIRE(support_copy(world, SPH_ATTRIBUTE_ID, (void**)&ids, &local) == SPH_OK, "local ids");
      for (uint32_t i = 0; i < local; ++i) emitted += ids[i] >= column_count ? 1u : 0u;
      holders = emitted > 0 ? 1u : 0u;
      MPI_Allreduce(MPI_IN_PLACE, &holders, 1, MPI_UINT32_T, MPI_SUM, MPI_COMM_WORLD);
      CHECK(g_size == 1 || holders >= 2, "frame %d: %u of %d ranks hold emitted particles (slab axis %d)", f,
            holders, g_size, counts.axis);
      free(ids);
    }
    snprintf(name, sizeof name, "source and sink, frame %d", f);
    expect_same_particles(single, world, name);
    free(mine_ids);
    free(all_ids);
    free(gathered);
    free(sizes);
    free(offsets);
  }
  if (g_rank == 0) {
    printf("the sink removed %u particles over the frames\n", removed_total);
    CHECK(removed_total > 0, "the sink removed nothing: the test does not exercise it");
  }
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
  run_capacity_limit(context);
  return mpi_test_finish(context, "mpi_sources");
}
