/* SPDX-License-Identifier: MIT */
/* Checkpoints of a distributed world (sph_mpi_world_save_file, _load_file, _restore_file) under
 * mpirun on 1-4 ranks. A stirred dam break (particles cross the slabs every few substeps) steps
 * 10 substeps and is saved; then:
 *   - it steps 10 more (A); restored from the save, it steps the same 10 again (B); a new world
 *     loaded from the save steps them too (C): A, B and C are equal bit for bit (a restored rank
 *     holds its particles in their saved order with their sort keys, and the slabs and counters
 *     as saved, so every sum adds in the same order: no tolerance);
 *   - the counts (global count, rebalances, migrations) after a restore are the saved world's;
 *   - a set with a missing rank file, a rank file of another save or a damaged manifest fails on
 *     every rank (each rank returns an error; the
 *     failing rank's code, the others the same code with the message naming the rank), and the
 *     world is unchanged after each (its gathered state equal bit for bit);
 *   - a communicator of another rank count loads the set (test_mpi_checkpoint_ranks.c steps it);
 *   - a rank's file is not a world (sph_world_load_file refuses it), and sph_world_save_file and
 *     sph_world_restore refuse a distributed world;
 *   - a DFSPH world whose density solve runs by conjugate gradients (its warm-start pressures
 *     travel in the rank files): A, B and C equal bit for bit too, the loaded world's solver
 *     the saved one's. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mpi_test_world.h"

#define N_SUBSTEPS 10
#define M_SUBSTEPS 10

static char g_dir[200];

static void path_of(char* out, size_t size, const char* name) { snprintf(out, size, "%s/%s", g_dir, name); }

static void counts_of(sph_world* world, sph_mpi_counts* c) {
  REQUIRE(sph_mpi_counts_init(c) == SPH_OK, "counts init");
  REQUIRE(sph_mpi_world_get_counts(world, c) == SPH_OK, "counts");
}

static int copy_file(const char* from, const char* to) {
  char buf[65536];
  size_t k;
  FILE* in = fopen(from, "rb");
  FILE* out = in ? fopen(to, "wb") : NULL;
  int ok = in && out;
  while (ok && (k = fread(buf, 1, sizeof buf, in)) > 0) ok = fwrite(buf, 1, k, out) == k;
  if (in) fclose(in);
  if (out) fclose(out);
  return ok;
}

/* A restore of `path` that must fail on every rank with `code`, naming `needle` on the rank that
 * failed (`culprit`, or every rank when -1) and the culprit on the others; the world unchanged. */
static void expect_failed_restore(sph_world* world, uint32_t n, const char* path, sph_result code,
                                  int culprit, const char* needle, const char* what) {
  float* x0 = NULL;
  float* v0 = NULL;
  float* x1 = NULL;
  float* v1 = NULL;
  sph_mpi_counts before, after;
  sph_result r;
  char rank_text[32];
  mpi_test_gather(world, n, &x0, &v0);
  counts_of(world, &before);
  r = sph_mpi_world_restore_file(world, path);
  CHECK(r == code, "%s: restore returned %d, expected %d", what, (int)r, (int)code);
  if (culprit < 0 || g_rank == culprit) {
    CHECK(strstr(sph_get_last_error(), needle) != NULL, "%s: the message names '%s': %s", what, needle,
          sph_get_last_error());
  } else {
    snprintf(rank_text, sizeof rank_text, "rank %d", culprit);
    CHECK(strstr(sph_get_last_error(), rank_text) != NULL, "%s: the message names %s: %s", what, rank_text,
          sph_get_last_error());
  }
  mpi_test_gather(world, n, &x1, &v1);
  counts_of(world, &after);
  CHECK(g_rank != 0 || mpi_differ(x0, v0, x1, v1, n, NULL) == 0, "%s: the world changed", what);
  CHECK(before.local_count == after.local_count && before.rebalances == after.rebalances &&
            before.migrated == after.migrated && before.slab_first == after.slab_first,
        "%s: the counts changed", what);
  free(x0);
  free(v0);
  free(x1);
  free(v1);
}

/* The stirred column on DFSPH with the conjugate gradients' density solve: saved after 4 substeps,
 * then 6 more from the live world (A), the restored one (B) and a loaded one (C). */
static void conjugate_gradients(sph_context* context) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world* loaded = NULL;
  sph_dfsph_params dfsph;
  sph_stats a_stats, b_stats, c_stats;
  uint32_t n = 0;
  float *ax = NULL, *av = NULL, *bx = NULL, *bv = NULL, *cx = NULL, *cv = NULL;
  char ck[256];
  path_of(ck, sizeof ck, "cg.sphck");
  mpi_test_world_def(&def);
  def.solver = SPH_SOLVER_DFSPH;
  mpi_test_dam(context, &def, 2.0f, NULL, NULL, &world, &n);
  REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK, "dfsph params init");
  dfsph.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
  dfsph.density_error = 1e-5f; /* (the convergence test, not the minimum, ends the solves) */
  REQUIRE(sph_world_set_dfsph_params(world, &dfsph) == SPH_OK, "dfsph params: %s", sph_get_last_error());
  mpi_test_step(world, 4, 1);
  REQUIRE(sph_mpi_world_save_file(world, ck) == SPH_OK, "save: %s", sph_get_last_error());
  mpi_test_step_stats(world, 6, 1, &a_stats);
  mpi_test_gather(world, n, &ax, &av);
  REQUIRE(sph_mpi_world_restore_file(world, ck) == SPH_OK, "restore: %s", sph_get_last_error());
  mpi_test_step_stats(world, 6, 1, &b_stats);
  mpi_test_gather(world, n, &bx, &bv);
  REQUIRE(sph_mpi_world_load_file(context, MPI_TEST_COMM, ck, &loaded) == SPH_OK, "load: %s",
          sph_get_last_error());
  sph_dfsph_params_init(&dfsph);
  REQUIRE(sph_world_get_dfsph_params(loaded, &dfsph) == SPH_OK, "dfsph params");
  CHECK(dfsph.linear_solver == SPH_DFSPH_CONJUGATE_GRADIENTS, "the loaded world's solver: %u",
        dfsph.linear_solver);
  mpi_test_step_stats(loaded, 6, 1, &c_stats);
  mpi_test_gather(loaded, n, &cx, &cv);
  CHECK(a_stats.pressure_iterations == b_stats.pressure_iterations &&
            a_stats.pressure_iterations == c_stats.pressure_iterations && a_stats.pressure_iterations > 0,
        "conjugate gradients: %u, %u and %u density iterations", a_stats.pressure_iterations,
        b_stats.pressure_iterations, c_stats.pressure_iterations);
  if (g_rank == 0) {
    const uint32_t restored_differ = mpi_differ(ax, av, bx, bv, n, NULL);
    const uint32_t loaded_differ = mpi_differ(ax, av, cx, cv, n, NULL);
    CHECK(restored_differ == 0 && loaded_differ == 0,
          "conjugate gradients: restored %u, loaded %u of %u particles differ", restored_differ,
          loaded_differ, n);
    printf(
        "checkpoint with DFSPH's conjugate gradients on %d ranks: %u particles, %u density iterations in %u "
        "substeps after the save: restored %u differ, loaded %u differ\n",
        g_size, n, a_stats.pressure_iterations, 6u, restored_differ, loaded_differ);
  }
  free(ax);
  free(av);
  free(bx);
  free(bv);
  free(cx);
  free(cv);
  REQUIRE(sph_world_destroy(loaded) == SPH_OK && sph_world_destroy(world) == SPH_OK, "destroy");
  {
    char name[300];
    if (mpi_test_rank_file(ck, g_rank, name, sizeof name)) remove(name);
    MPI_Barrier(MPI_COMM_WORLD);
    if (g_rank == 0) remove(ck);
  }
}

int main(int argc, char** argv) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* world = NULL;
  sph_world* loaded = NULL;
  sph_world* plain = NULL;
  sph_mpi_counts saved, restored;
  uint32_t n = 0;
  float *ax = NULL, *av = NULL, *bx = NULL, *bv = NULL, *cx = NULL, *cv = NULL;
  char ck[256], ck2[256], file[300], other[300], aside[400];
  sph_result r;
  mpi_test_init(&argc, &argv, &context);
  if (g_rank == 0) {
    snprintf(g_dir, sizeof g_dir, "%s/sph_mpi_checkpoint_XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    REQUIRE(mkdtemp(g_dir) != NULL, "mkdtemp");
  }
  MPI_Bcast(g_dir, sizeof g_dir, MPI_CHAR, 0, MPI_COMM_WORLD);
  path_of(ck, sizeof ck, "dam.sphck");
  path_of(ck2, sizeof ck2, "later.sphck");

  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 2.0f, NULL, NULL, &world, &n);
  mpi_test_step(world, N_SUBSTEPS, 1);
  r = sph_mpi_world_save_file(world, ck);
  REQUIRE(r == SPH_OK, "save: %d", (int)r);
  counts_of(world, &saved);

  /* A: on from the live world; B: on from the restored one; C: on from a loaded one. */
  mpi_test_step(world, M_SUBSTEPS, 1);
  mpi_test_gather(world, n, &ax, &av);
  r = sph_mpi_world_restore_file(world, ck);
  REQUIRE(r == SPH_OK, "restore: %d", (int)r);
  counts_of(world, &restored);
  CHECK(restored.global_count == n && restored.local_count == saved.local_count &&
            restored.rebalances == saved.rebalances && restored.migrated == saved.migrated &&
            restored.axis == saved.axis && restored.slab_first == saved.slab_first &&
            restored.slab_last == saved.slab_last,
        "the restored counts are not the saved ones");
  mpi_test_step(world, M_SUBSTEPS, 1);
  mpi_test_gather(world, n, &bx, &bv);
  r = sph_mpi_world_load_file(context, MPI_TEST_COMM, ck, &loaded);
  REQUIRE(r == SPH_OK && loaded != NULL, "load: %d", (int)r);
  mpi_test_step(loaded, M_SUBSTEPS, 1);
  mpi_test_gather(loaded, n, &cx, &cv);
  if (g_rank == 0) {
    const uint32_t restored_differ = mpi_differ(ax, av, bx, bv, n, NULL);
    const uint32_t loaded_differ = mpi_differ(ax, av, cx, cv, n, NULL);
    CHECK(restored_differ == 0, "restored and stepped %u substeps: %u of %u particles differ", M_SUBSTEPS,
          restored_differ, n);
    CHECK(loaded_differ == 0, "loaded and stepped %u substeps: %u of %u particles differ", M_SUBSTEPS,
          loaded_differ, n);
    printf(
        "checkpoint on %d ranks: %u particles, saved after %u substeps, %u more: restored %u differ, loaded "
        "%u differ (%llu migrations, %u rebalances at the save)\n",
        g_size, n, N_SUBSTEPS, M_SUBSTEPS, restored_differ, loaded_differ, (unsigned long long)saved.migrated,
        saved.rebalances);
  }
  CHECK(saved.rebalances >= 1 && (g_size == 1 || saved.migrated > 0), "no migration before the save");
  /* A later state's set, for a rank file of another save. */
  REQUIRE(sph_mpi_world_save_file(loaded, ck2) == SPH_OK, "second save");
  REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");

  /* Failures, each on one rank (the last), agreed by every rank. */
  REQUIRE(mpi_test_rank_file(ck, g_size - 1, file, sizeof file), "the manifest names the last rank's file");
  REQUIRE(mpi_test_rank_file(ck2, g_size - 1, other, sizeof other), "the second manifest too");
  snprintf(aside, sizeof aside, "%s.aside", file);
  if (g_rank == g_size - 1) REQUIRE(rename(file, aside) == 0, "rename");
  MPI_Barrier(MPI_COMM_WORLD);
  expect_failed_restore(world, n, ck, SPH_ERROR_INVALID_ARGUMENT, g_size - 1, "rank", "a missing rank file");
  if (g_rank == g_size - 1) REQUIRE(copy_file(other, file), "copy");
  MPI_Barrier(MPI_COMM_WORLD);
  expect_failed_restore(world, n, ck, SPH_ERROR_CORRUPT_DATA, g_size - 1, "another save",
                        "a rank file of another save");
  if (g_rank == g_size - 1) REQUIRE(rename(aside, file) == 0, "rename back");
  if (g_rank == 0) {
    /* The manifest cut short by one byte (a later copy of it is kept aside). */
    FILE* f = fopen(ck, "rb");
    char buf[4096];
    size_t k;
    REQUIRE(f != NULL, "open manifest");
    k = fread(buf, 1, sizeof buf, f);
    fclose(f);
    snprintf(aside, sizeof aside, "%s.aside", ck);
    REQUIRE(copy_file(ck, aside), "copy manifest");
    f = fopen(ck, "wb");
    REQUIRE(f != NULL && fwrite(buf, 1, k - 1, f) == k - 1, "write manifest");
    fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  expect_failed_restore(world, n, ck, SPH_ERROR_CORRUPT_DATA, -1, "manifest", "a damaged manifest");
  if (g_rank == 0) REQUIRE(rename(aside, ck) == 0, "manifest back");
  MPI_Barrier(MPI_COMM_WORLD);
  expect_failed_restore(world, n, NULL, SPH_ERROR_INVALID_ARGUMENT, -1, "path", "a NULL path");
  if (g_size > 1) {
    /* Another rank count loads it too (test_mpi_checkpoint_ranks.c steps such worlds): rank 0
     * alone, and the others together, each a whole world. */
    MPI_Comm half;
    sph_world* w = NULL;
    sph_mpi_counts c;
    MPI_Comm_split(MPI_COMM_WORLD, g_rank == 0 ? 0 : 1, g_rank, &half);
    r = sph_mpi_world_load_file(context, (int32_t)MPI_Comm_c2f(half), ck, &w);
    CHECK(r == SPH_OK && w != NULL, "a load on another rank count: %d %s", (int)r, sph_get_last_error());
    if (w) {
      counts_of(w, &c);
      CHECK(c.global_count == n, "loaded on another rank count: %llu particles, saved %u",
            (unsigned long long)c.global_count, n);
      REQUIRE(sph_world_destroy(w) == SPH_OK, "destroy");
    }
    MPI_Comm_free(&half);
  }
  /* The set is whole again: it restores. */
  REQUIRE(sph_mpi_world_restore_file(world, ck) == SPH_OK, "restore of the repaired set");

  /* Arguments refused on the last rank alone (since session 37; before, that rank returned while
   * the others went on: a save then wrote the rank's file where the manifest does not look, a load
   * left the others in MPI_Comm_dup or with a world of another set): every rank refuses. */
  if (g_size > 1) {
    char elsewhere[256];
    sph_world* w = NULL;
    path_of(elsewhere, sizeof elsewhere, "elsewhere.sphck");
    r = sph_mpi_world_save_file(world, g_rank == g_size - 1 ? elsewhere : ck2);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "same checkpoint"),
          "a save to another path on the last rank: rank %d returned %d (%s)", g_rank, (int)r,
          sph_get_last_error());
    CHECK(access(elsewhere, F_OK) != 0, "the refused save wrote %s", elsewhere);
    expect_failed_restore(world, n, g_rank == g_size - 1 ? ck2 : ck, SPH_ERROR_INVALID_ARGUMENT, -1,
                          "same checkpoint", "a restore from another path on the last rank");
    r = sph_mpi_world_load_file(context, MPI_TEST_COMM, g_rank == g_size - 1 ? ck2 : ck, &w);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && w == NULL, "a load from another path on the last rank: %d (%s)",
          (int)r, sph_get_last_error());
  }
  {
    sph_world* w = NULL;
    r = sph_mpi_world_load_file(context, MPI_TEST_COMM, ck, g_rank == g_size - 1 ? NULL : &w);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && w == NULL,
          "a load with a NULL out on the last rank: rank %d %d (%s)", g_rank, (int)r, sph_get_last_error());
    CHECK(g_rank == g_size - 1 || strstr(sph_get_last_error(), "rank") != NULL,
          "a load with a NULL out elsewhere: the message names the rank: %s", sph_get_last_error());
  }

  /* A crash after the ranks renamed their files in and before rank 0 replaced the manifest
   * leaves the new files beside the old manifest under names of their own (the file's hash in
   * the name): emulated with the later set's files renamed to the names a save to `ck` would give
   * them. The old set restores, with the saved counts. */
  {
    char later[300], orphan[400], mine[300];
    const char* base = strrchr(ck2, '/') + 1;
    REQUIRE(mpi_test_rank_file(ck2, g_rank, later, sizeof later), "the later set's file");
    snprintf(orphan, sizeof orphan, "%s/dam.sphck%s", g_dir, strrchr(later, '/') + 1 + strlen(base));
    REQUIRE(rename(later, orphan) == 0, "rename %s to %s", later, orphan);
    MPI_Barrier(MPI_COMM_WORLD);
    r = sph_mpi_world_restore_file(world, ck);
    CHECK(r == SPH_OK, "restore beside a crashed save's files: %d %s", (int)r, sph_get_last_error());
    counts_of(world, &restored);
    CHECK(restored.global_count == n && restored.local_count == saved.local_count &&
              restored.migrated == saved.migrated,
          "the old set restored other counts beside a crashed save's files");
    /* A save to the same path replaces the set: new names, the old set's files removed once the
     * new manifest is in place (the crashed save's orphan is not the manifest's to remove). */
    REQUIRE(mpi_test_rank_file(ck, g_rank, mine, sizeof mine), "this rank's file");
    mpi_test_step(world, 1, 1);
    REQUIRE(sph_mpi_world_save_file(world, ck) == SPH_OK, "save over a set: %s", sph_get_last_error());
    REQUIRE(mpi_test_rank_file(ck, g_rank, later, sizeof later), "this rank's new file");
    CHECK(strcmp(mine, later) != 0, "a later state's file has the old name %s", mine);
    CHECK(access(mine, F_OK) != 0, "rank %d's file of the replaced set is left: %s", g_rank, mine);
    CHECK(access(later, F_OK) == 0, "rank %d's new file is missing", g_rank);
    REQUIRE(sph_mpi_world_restore_file(world, ck) == SPH_OK, "restore of the new set");
    remove(orphan);
  }

  /* The single-world calls, on the last rank's file of the set now saved. */
  REQUIRE(mpi_test_rank_file(ck, g_size - 1, file, sizeof file), "the last rank's file");
  r = sph_world_load_file(context, file, &plain);
  CHECK(r == SPH_ERROR_INVALID_ARGUMENT && plain == NULL, "sph_world_load_file of a rank's file: %d", (int)r);
  CHECK(strstr(sph_get_last_error(), "manifest") != NULL, "the message points to the manifest: %s",
        sph_get_last_error());
  snprintf(aside, sizeof aside, "%s/plain.sphck.%d", g_dir, g_rank);
  CHECK(sph_world_save_file(world, aside) == SPH_ERROR_UNSUPPORTED,
        "sph_world_save_file of a distributed world");
  {
    const char junk[64] = {0};
    CHECK(sph_world_restore(world, junk, sizeof junk) == SPH_ERROR_UNSUPPORTED,
          "sph_world_restore of a distributed world");
  }

  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  conjugate_gradients(context);
  MPI_Barrier(MPI_COMM_WORLD);
  {
    char name[300];
    if (mpi_test_rank_file(ck, g_rank, name, sizeof name)) remove(name);
    MPI_Barrier(MPI_COMM_WORLD);
    if (g_rank == 0) {
      remove(ck);
      remove(ck2);
      rmdir(g_dir);
    }
  }
  free(ax);
  free(av);
  free(bx);
  free(bv);
  free(cx);
  free(cv);
  return mpi_test_finish(context, "mpi checkpoint");
}
