/* SPDX-License-Identifier: MIT */
/* Checkpoints of a distributed world on another rank count than saved them, and a failed save,
 * under mpirun -np 3. The stirred dam break of test_mpi_checkpoint.c steps 10 substeps on 2 ranks
 * (ranks 0-1) and on 3, each saved; then:
 *   - the 2-rank set loaded on 1 rank and on 3, the 3-rank set loaded on 2, and the 2-rank set
 *     restored into a 3-rank world, each stepped 10 more substeps, equal the undivided world
 *     stepped 10 + 10 bit for bit: every particle keeps its sort key, which orders the next sort
 *     on any rank count alike (docs/distributed.md), so every sum adds in the undivided world's
 *     order; no tolerance;
 *   - after a load on another rank count each rank holds the particles of its block of the saved
 *     files (a rank without one holds none) until the first frame cuts the slabs anew;
 *   - DFSPH's warm starts and the user attribute travel with the particles (a DFSPH world saved
 *     on 2 ranks and loaded on 3: the undivided world's bits, every attribute kept);
 *   - max_capacity is per rank: a set whose particles do not fit one rank's max_capacity fails
 *     to load on 1 rank with SPH_ERROR_CAPACITY;
 *   - a save that fails on one rank (its staged file's name taken by a directory) fails on every
 *     rank and leaves the old set byte for byte (manifest and every rank file) with no staged
 *     file beside it; the old set still loads and steps to the undivided world's state. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mpi_test_world.h"
#include "support.h"

#define N_SUBSTEPS 10
#define M_SUBSTEPS 10

static char g_dir[200];

/* A file's bytes (malloc'd, *size), NULL when it cannot be read. */
static unsigned char* slurp(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  unsigned char* bytes = NULL;
  long n;
  *size = 0;
  if (!f) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
    bytes = (unsigned char*)malloc((size_t)n + 1);
    if (bytes && fread(bytes, 1, (size_t)n, f) == (size_t)n) {
      *size = (size_t)n;
    } else {
      free(bytes);
      bytes = NULL;
    }
  }
  fclose(f);
  return bytes;
}

/* The world on `comm`, stepped M_SUBSTEPS, against the undivided world's reference (rank 0). */
static void expect_reference(sph_world* world, MPI_Comm comm, uint32_t n, const float* rx, const float* rv,
                             const char* what) {
  float *x = NULL, *v = NULL;
  int rank;
  MPI_Comm_rank(comm, &rank);
  mpi_test_step(world, M_SUBSTEPS, 1);
  mpi_test_gather_on(world, comm, n, &x, &v);
  if (rank == 0) {
    const uint32_t differ = mpi_differ(rx, rv, x, v, n, NULL);
    CHECK(differ == 0, "%s: %u of %u particles differ from the undivided world", what, differ, n);
    printf("%s, %u more substeps: %u of %u particles differ from the undivided world\n", what, M_SUBSTEPS,
           differ, n);
  }
  free(x);
  free(v);
}

/* This rank's ids and user attributes (malloc'd), *n of them. */
static void read_ids_and_users(sph_world* world, uint32_t** ids, uint32_t** users, uint32_t* n) {
  sph_mpi_counts c;
  uint32_t got = 0;
  REQUIRE(sph_mpi_counts_init(&c) == SPH_OK, "counts init");
  REQUIRE(sph_mpi_world_get_counts(world, &c) == SPH_OK, "counts");
  *n = c.local_count;
  *ids = (uint32_t*)malloc(4 * ((size_t)*n + 1));
  *users = (uint32_t*)malloc(4 * ((size_t)*n + 1));
  REQUIRE(*ids && *users, "malloc");
  REQUIRE(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, *ids, 4ull * *n, 4, 0, *n, &got) == SPH_OK &&
              got == *n,
          "ids");
  REQUIRE(sph_world_copy_attribute(world, SPH_ATTRIBUTE_USER, *users, 4ull * *n, 4, 0, *n, &got) == SPH_OK &&
              got == *n,
          "user attributes");
}

/* DFSPH's warm starts (carried pressures) and the user attribute travel with the particles: a
 * DFSPH world whose particles carry the attribute 3 id + 1, saved on 2 ranks after 5 + 5
 * substeps and loaded on 3, steps 10 more to the undivided world's bits, each particle still
 * carrying 3 id + 1. */
static void carried_arrays(sph_context* context, MPI_Comm comm2, const char* path) {
  sph_world_def def;
  sph_world *single = NULL, *w2 = NULL, *loaded = NULL;
  uint32_t n = 0, k, mine, *ids = NULL, *users = NULL, wrong = 0;
  float *rx = NULL, *rv = NULL;
  mpi_test_world_def(&def);
  def.solver = SPH_SOLVER_DFSPH;
  def.features = SPH_FEATURE_USER_ATTRIBUTE;
  if (comm2 != MPI_COMM_NULL) {
    mpi_test_dam_on(context, &def, 2.0f, comm2, NULL, &single, &w2, &n);
    mpi_test_step(w2, 5, 1);
    read_ids_and_users(w2, &ids, &users, &mine);
    for (k = 0; k < mine; ++k) users[k] = 3u * ids[k] + 1u;
    REQUIRE(sph_world_set_attribute(w2, SPH_ATTRIBUTE_USER, users, 4ull * mine, 4, 0, mine) == SPH_OK,
            "set users");
    free(ids);
    free(users);
    mpi_test_step(w2, 5, 1);
    REQUIRE(sph_mpi_world_save_file(w2, path) == SPH_OK, "save the DFSPH world on 2 ranks");
    REQUIRE(sph_world_destroy(w2) == SPH_OK, "destroy");
  }
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  if (g_rank == 0) {
    mpi_test_step(single, 5, 0);
    mpi_test_step(single, 5, 0);
    mpi_test_step(single, M_SUBSTEPS, 0);
    mpi_test_read(single, n, &rx, &rv);
    sph_world_destroy(single);
  }
  REQUIRE(sph_mpi_world_load_file(context, MPI_TEST_COMM, path, &loaded) == SPH_OK,
          "load the DFSPH world on 3: %s", sph_get_last_error());
  expect_reference(loaded, MPI_COMM_WORLD, n, rx, rv,
                   "DFSPH with the user attribute, saved on 2 ranks, loaded on 3");
  read_ids_and_users(loaded, &ids, &users, &mine);
  for (k = 0; k < mine; ++k) wrong += users[k] != 3u * ids[k] + 1u;
  CHECK(wrong == 0, "rank %d: %u of %u particles lost their user attribute", g_rank, wrong, mine);
  free(ids);
  free(users);
  free(rx);
  free(rv);
  REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");
}

/* max_capacity is per rank: a world of max_capacity 1000 whose 2 ranks each added half of the
 * 1404-particle column saves fine, but its 1404 particles do not fit one rank: a load on 1 rank
 * fails with SPH_ERROR_CAPACITY naming max_capacity, and creates no world. */
static void capacity_refusal(sph_context* context, MPI_Comm comm1, MPI_Comm comm2, const char* path) {
  static const support_tank kTank = {{0.2f, 0.1f, 0.03f}, {0.2f, 0.1f, 0.03f}, 0.005f, 0.0f};
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_world_def def;
  sph_world *scratch = NULL, *w2 = NULL, *loaded = NULL;
  float* positions = NULL;
  uint32_t n = 0, half;
  int rank2;
  sph_result r;
  mpi_test_world_def(&def);
  def.capacity = 1000;
  def.max_capacity = 1000;
  if (comm2 != MPI_COMM_NULL) {
    sph_world_def big = def;
    big.capacity = big.max_capacity = 4096;
    MPI_Comm_rank(comm2, &rank2);
    /* Every rank of comm2 makes the column and adds its half (ids in rank order). */
    REQUIRE(sph_world_create(context, &big, &scratch) == SPH_OK, "scratch world");
    REQUIRE(support_dam_break(context, scratch, &kTank, column_min, column_max, NULL, NULL, &n) == SPH_OK,
            "dam");
    REQUIRE(support_copy_by_id(scratch, SPH_ATTRIBUTE_POSITION, (void**)&positions, &n) == SPH_OK,
            "positions");
    sph_world_destroy(scratch);
    half = n / 2;
    REQUIRE(sph_mpi_world_create(context, &def, (int32_t)MPI_Comm_c2f(comm2), NULL, &w2) == SPH_OK, "world");
    REQUIRE(support_tank_create(context, w2, &kTank, NULL, NULL) == SPH_OK, "tank");
    REQUIRE(sph_mpi_world_add_particles(w2, positions + (rank2 == 0 ? 0 : 3 * (size_t)half), NULL,
                                        rank2 == 0 ? half : n - half, NULL) == SPH_OK,
            "add halves: %s", sph_get_last_error());
    free(positions);
    mpi_test_step(w2, 2, 1);
    REQUIRE(sph_mpi_world_save_file(w2, path) == SPH_OK, "save: %s", sph_get_last_error());
    REQUIRE(sph_world_destroy(w2) == SPH_OK, "destroy");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm1 != MPI_COMM_NULL) {
    r = sph_mpi_world_load_file(context, (int32_t)MPI_Comm_c2f(comm1), path, &loaded);
    CHECK(r == SPH_ERROR_CAPACITY && loaded == NULL, "1404 particles on one rank of max_capacity 1000: %d",
          (int)r);
    CHECK(strstr(sph_get_last_error(), "max_capacity") != NULL, "the message names max_capacity: %s",
          sph_get_last_error());
    if (loaded) sph_world_destroy(loaded);
  }
}

static void local_count(sph_world* world, sph_mpi_counts* c) {
  REQUIRE(sph_mpi_counts_init(c) == SPH_OK, "counts init");
  REQUIRE(sph_mpi_world_get_counts(world, c) == SPH_OK, "counts");
}

int main(int argc, char** argv) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world *single = NULL, *w2 = NULL, *w3 = NULL, *loaded = NULL;
  sph_mpi_counts saved2, c;
  MPI_Comm comm1, comm2;
  uint32_t n = 0, n3 = 0;
  float *rx = NULL, *rv = NULL;
  char ck2[256], ck3[256], ckd[256], ckc[256], name[300];
  sph_result r;
  mpi_test_init(&argc, &argv, &context);
  if (g_size != 3) {
    if (g_rank == 0) printf("mpi_checkpoint_ranks runs on 3 ranks (mpirun -np 3), not %d\n", g_size);
    MPI_Finalize();
    return 1;
  }
  if (g_rank == 0) {
    snprintf(g_dir, sizeof g_dir, "%s/sph_mpi_ck_ranks_XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    REQUIRE(mkdtemp(g_dir) != NULL, "mkdtemp");
  }
  MPI_Bcast(g_dir, sizeof g_dir, MPI_CHAR, 0, MPI_COMM_WORLD);
  snprintf(ck2, sizeof ck2, "%s/two.sphck", g_dir);
  snprintf(ck3, sizeof ck3, "%s/three.sphck", g_dir);
  snprintf(ckd, sizeof ckd, "%s/dfsph.sphck", g_dir);
  snprintf(ckc, sizeof ckc, "%s/capacity.sphck", g_dir);
  MPI_Comm_split(MPI_COMM_WORLD, g_rank == 0 ? 0 : MPI_UNDEFINED, g_rank, &comm1);
  MPI_Comm_split(MPI_COMM_WORLD, g_rank < 2 ? 0 : MPI_UNDEFINED, g_rank, &comm2);
  mpi_test_world_def(&def);

  /* Saved on 2 ranks after N substeps; the undivided world (rank 0) steps the same 10 + 10. */
  if (comm2 != MPI_COMM_NULL) {
    mpi_test_dam_on(context, &def, 2.0f, comm2, NULL, &single, &w2, &n);
    mpi_test_step(w2, N_SUBSTEPS, 1);
    REQUIRE(sph_mpi_world_save_file(w2, ck2) == SPH_OK, "save on 2 ranks");
    local_count(w2, &saved2);
    REQUIRE(sph_world_destroy(w2) == SPH_OK, "destroy");
  }
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  MPI_Bcast(&saved2.local_count, 1, MPI_UINT32_T, 1, MPI_COMM_WORLD); /* rank 1's file */
  if (g_rank == 0) {
    mpi_test_step(single, N_SUBSTEPS, 0);
    mpi_test_step(single, M_SUBSTEPS, 0);
    mpi_test_read(single, n, &rx, &rv);
  }

  /* 2 -> 1. */
  if (comm1 != MPI_COMM_NULL) {
    REQUIRE(sph_mpi_world_load_file(context, (int32_t)MPI_Comm_c2f(comm1), ck2, &loaded) == SPH_OK,
            "load on 1 rank: %s", sph_get_last_error());
    local_count(loaded, &c);
    CHECK(c.local_count == n && c.global_count == n, "on 1 rank: %u particles, the world %llu, expected %u",
          c.local_count, (unsigned long long)c.global_count, n);
    expect_reference(loaded, comm1, n, rx, rv, "saved on 2 ranks, loaded on 1");
    REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");
  }
  /* 2 -> 3: rank 0 takes no file, ranks 1 and 2 one each (rank_part_join.h's blocks). */
  r = sph_mpi_world_load_file(context, MPI_TEST_COMM, ck2, &loaded);
  REQUIRE(r == SPH_OK, "load on 3 ranks: %d %s", (int)r, sph_get_last_error());
  local_count(loaded, &c);
  CHECK(c.global_count == n, "loaded on 3 ranks: %llu particles", (unsigned long long)c.global_count);
  CHECK(g_rank != 0 || c.local_count == 0, "rank 0 holds %u particles before the first frame", c.local_count);
  CHECK(g_rank != 2 || c.local_count == saved2.local_count, "rank 2 holds %u particles, saved rank 1 %u",
        c.local_count, saved2.local_count);
  expect_reference(loaded, MPI_COMM_WORLD, n, rx, rv, "saved on 2 ranks, loaded on 3");
  local_count(loaded, &c);
  CHECK(c.local_count > 0, "rank %d holds no particle after the first frame's cut", g_rank);
  REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");

  /* 3 -> 2, and the 2-rank set restored into the 3-rank world. */
  mpi_test_dam_on(context, &def, 2.0f, MPI_COMM_WORLD, NULL, NULL, &w3, &n3);
  REQUIRE(n3 == n, "the same dam");
  mpi_test_step(w3, N_SUBSTEPS, 1);
  REQUIRE(sph_mpi_world_save_file(w3, ck3) == SPH_OK, "save on 3 ranks");
  if (comm2 != MPI_COMM_NULL) {
    REQUIRE(sph_mpi_world_load_file(context, (int32_t)MPI_Comm_c2f(comm2), ck3, &loaded) == SPH_OK,
            "load on 2 ranks: %s", sph_get_last_error());
    expect_reference(loaded, comm2, n, rx, rv, "saved on 3 ranks, loaded on 2");
    REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");
  }
  REQUIRE(sph_mpi_world_restore_file(w3, ck2) == SPH_OK, "restore of the 2-rank set: %s",
          sph_get_last_error());
  expect_reference(w3, MPI_COMM_WORLD, n, rx, rv, "saved on 2 ranks, restored into a 3-rank world");

  /* A failed save: a directory where rank 2 stages its file. */
  {
    unsigned char *before = NULL, *after = NULL, *mb = NULL, *ma = NULL;
    size_t bn, an, mbn = 0, man = 0;
    char rank_file[300], staged[320];
    struct stat st;
    REQUIRE(mpi_test_rank_file(ck3, g_rank, rank_file, sizeof rank_file), "this rank's file");
    snprintf(staged, sizeof staged, "%s.rank%d.staged", ck3, g_rank);
    before = slurp(rank_file, &bn);
    if (g_rank == 0) mb = slurp(ck3, &mbn);
    REQUIRE(before != NULL && (g_rank != 0 || mb != NULL), "read the set");
    if (g_rank == 2) REQUIRE(mkdir(staged, 0755) == 0, "mkdir");
    MPI_Barrier(MPI_COMM_WORLD);
    r = sph_mpi_world_save_file(w3, ck3);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT, "a save that fails on rank 2 returned %d", (int)r);
    CHECK(strstr(sph_get_last_error(), g_rank == 2 ? "staged" : "rank 2") != NULL,
          "the message names the failure: %s", sph_get_last_error());
    MPI_Barrier(MPI_COMM_WORLD);
    after = slurp(rank_file, &an);
    CHECK(after && an == bn && memcmp(before, after, bn) == 0, "rank %d's file changed in a failed save",
          g_rank);
    CHECK(g_rank == 2 || stat(staged, &st) != 0, "rank %d's staged file is left after a failed save", g_rank);
    if (g_rank == 0) {
      ma = slurp(ck3, &man);
      CHECK(ma && man == mbn && memcmp(mb, ma, mbn) == 0, "the manifest changed in a failed save");
    }
    free(before);
    free(after);
    free(mb);
    free(ma);
    if (g_rank == 2) REQUIRE(rmdir(staged) == 0, "rmdir");
    MPI_Barrier(MPI_COMM_WORLD);
  }
  REQUIRE(sph_mpi_world_restore_file(w3, ck3) == SPH_OK, "restore of the set a failed save left");
  expect_reference(w3, MPI_COMM_WORLD, n, rx, rv, "saved on 3 ranks, a failed save later, restored");
  REQUIRE(sph_world_destroy(w3) == SPH_OK, "destroy");

  carried_arrays(context, comm2, ckd);
  capacity_refusal(context, comm1, comm2, ckc);

  /* Clean up (each rank its own files; rank 2's of the 2-rank sets does not exist). */
  MPI_Barrier(MPI_COMM_WORLD);
  if (mpi_test_rank_file(ck3, g_rank, name, sizeof name)) remove(name);
  if (mpi_test_rank_file(ck2, g_rank, name, sizeof name)) remove(name);
  if (mpi_test_rank_file(ckd, g_rank, name, sizeof name)) remove(name);
  if (mpi_test_rank_file(ckc, g_rank, name, sizeof name)) remove(name);
  MPI_Barrier(MPI_COMM_WORLD);
  if (g_rank == 0) {
    remove(ck2);
    remove(ck3);
    remove(ckd);
    remove(ckc);
    rmdir(g_dir);
    sph_world_destroy(single);
  }
  if (comm1 != MPI_COMM_NULL) MPI_Comm_free(&comm1);
  if (comm2 != MPI_COMM_NULL) MPI_Comm_free(&comm2);
  free(rx);
  free(rv);
  return mpi_test_finish(context, "mpi checkpoint ranks");
}
