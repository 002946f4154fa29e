/* SPDX-License-Identifier: MIT */
/* Springs across ranks against one undivided world on the same backend (mpi_springs_cases.h):
 * the cases of tests/mpi/test_mpi_springs.c (CPU ranks, ctest) and of gpu_check_mpi (CUDA ranks,
 * tests/mpi/test_mpi_cuda.c). The column of 1404 particles in its
 * tank, stirred at up to 2 m/s so that particles, and the two ends of springs, cross the slab
 * boundaries; every particle links to its 12 lattice neighbours at its first substep. Cases:
 *   - elastic springs (k = 1e4 1/s^2, damping 20 1/s): the spring ends on both sides of a cut
 *     read each other as ghosts;
 *   - weak elastic springs (k = 100 1/s^2, 30 substeps at 4 m/s): an elastic spring has no
 *     longest length, and here springs stretch across two cell layers or more along the slabs'
 *     axis (counted by brute force over the linked pairs: at least one, so the case exercises
 *     it), past the halo, one layer deep: their far ends come as spring ghosts;
 *   - plastic springs (alpha = 200 1/s, gamma 0.05): rest lengths flow and springs past h drop,
 *     on both ranks of a spring alike;
 *   - a sink over the column's top: springs whose partner it removed are dropped;
 *   - a block added after 5 substeps by the last rank alone: every rank links in the same
 *     substep (the lowest waiting id is reduced over the ranks) and the block's particles find
 *     their partners across the cuts;
 *   - RK4 (each stage sorts, resolves and returns the lists to ids) and DFSPH;
 *   - DFSPH by conjugate gradients with weak springs: spring ghosts (which no share of the solve
 *     reaches) inside the CG solve, whose ranks skip their ghosts' walks (coverage: no owned
 *     particle's walk reads a spring ghost's velocity step, so the bits do not show whether it is
 *     written 0 or left stale).
 * Each: after the substeps, the particles equal the undivided world's bit for bit (the spring
 * sums run over the same slots with the same partners' bits: no tolerance), the count is the
 * world's. Also rank checkpoints of a world with springs, restored, loaded, and loaded on one rank,
 * and an add refused on one rank leaving every rank's checkpoint bytes as they were. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mpi_compare.h"
#include "mpi_springs_cases.h"
#include "mpi_test_world.h"
#include "sph_c.h"
#include "sph_mpi.h"
#include "support.h"

static int compare_u32(const void* a, const void* b) {
  const uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

typedef struct spring_case {
  const char* name;
  float stir;        /* m/s */
  float stiffness;   /* 1/s^2 */
  float damping;     /* 1/s */
  float plasticity;  /* 1/s */
  float yield_ratio; /* gamma */
  int sink;          /* a sink over y > 0.185 m */
  int late_block;    /* a block added by the last rank after 5 substeps */
  int want_far;      /* some spring spans two cell layers or more at the end */
  sph_integrator integrator;
  sph_solver solver;
  uint32_t substeps;
  uint32_t linear_solver; /* DFSPH's density solve (sph_dfsph_params.linear_solver); 0: the default */
} spring_case;

static void set_springs(sph_world* w, const spring_case* c) {
  sph_spring_params p;
  REQUIRE(sph_spring_params_init(&p) == SPH_OK, "spring params init");
  REQUIRE(sph_world_get_spring_params(w, &p) == SPH_OK, "spring params");
  p.stiffness = c->stiffness;
  p.damping = c->damping;
  p.plasticity = c->plasticity;
  p.yield_ratio = c->yield_ratio;
  REQUIRE(sph_world_set_spring_params(w, &p) == SPH_OK, "set spring params");
  if (c->linear_solver) {
    sph_dfsph_params dfsph;
    REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK, "dfsph params init");
    dfsph.linear_solver = c->linear_solver;
    REQUIRE(sph_world_set_dfsph_params(w, &dfsph) == SPH_OK, "dfsph params: %s", sph_get_last_error());
  }
}

/* Rank 0: the linked pairs of the first n ids (closer than the link radius, 1.2 spacings, at
 * `x`, by id: every lattice neighbour, 12 at most, fits the 16 slots), as pairs of ids. */
static uint32_t* linked_pairs(const float* x, uint32_t n, uint32_t* count) {
  const float link = 1.2f * MPI_TEST_SPACING;
  size_t cap = 16 * (size_t)n + 1, k = 0;
  uint32_t* pairs = (uint32_t*)malloc(sizeof(uint32_t) * 2 * cap);
  REQUIRE(pairs != NULL, "malloc");
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = i + 1; j < n; ++j) {
      const float dx = x[3 * i] - x[3 * j], dy = x[3 * i + 1] - x[3 * j + 1],
                  dz = x[3 * i + 2] - x[3 * j + 2];
      if (dx * dx + dy * dy + dz * dz < link * link && k < cap) {
        pairs[2 * k] = i;
        pairs[2 * k + 1] = j;
        ++k;
      }
    }
  *count = (uint32_t)k;
  return pairs;
}

/* Rank 0: how many pairs (both ends still in the undivided world) lie two cell layers or more
 * apart along `axis` (their springs span past a one-layer halo wherever a cut runs between). */
static uint32_t far_pairs(sph_world* single, const uint32_t* pairs, uint32_t count, int axis) {
  uint32_t* ids = NULL;
  float* x = NULL;
  float* v = NULL;
  uint32_t far = 0;
  const uint32_t m = read_in_id_order(single, &ids, &x, &v);
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t* a = (const uint32_t*)bsearch(&pairs[2 * k], ids, m, sizeof(uint32_t), compare_u32);
    const uint32_t* b = (const uint32_t*)bsearch(&pairs[2 * k + 1], ids, m, sizeof(uint32_t), compare_u32);
    if (!a || !b) continue;
    {
      const float xa = x[3 * (size_t)(a - ids) + (size_t)axis], xb = x[3 * (size_t)(b - ids) + (size_t)axis];
      const int32_t la = (int32_t)floorf(xa / MPI_TEST_KERNEL_RADIUS),
                    lb = (int32_t)floorf(xb / MPI_TEST_KERNEL_RADIUS);
      if (la - lb >= 2 || lb - la >= 2) ++far;
    }
  }
  free(ids);
  free(x);
  free(v);
  return far;
}

/* The world def of every case: the test world's, at `capacity` (0: its own), with springs. */
static void springs_def(sph_world_def* def, uint32_t capacity) {
  mpi_test_world_def(def);
  if (capacity) def->capacity = capacity;
  def->features = SPH_FEATURE_SPRINGS;
}

/* A checkpoint path of this run's own, `stem`.np<ranks>.<run>.sphcp: ctest -j2 runs mpi_springs_np1
 * and _np2 side by side in one folder, and with one name each restored the other's save (CI,
 * session 24). The run is rank 0's process id, shared. */
static void run_checkpoint_path(char* path, size_t size, const char* stem) {
  long run_id = (long)getpid();
  MPI_Bcast(&run_id, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  snprintf(path, size, "%s.np%d.%ld.sphcp", stem, g_size, run_id);
}

/* Removes the set saved at `path`: each rank its file, then rank 0 the manifest. */
static void remove_saved_set(const char* path) {
  char name[512];
  MPI_Barrier(MPI_COMM_WORLD);
  if (mpi_test_rank_file(path, g_rank, name, sizeof name)) remove(name);
  MPI_Barrier(MPI_COMM_WORLD);
  if (g_rank == 0) remove(path);
}

static void run_case(sph_context* context, uint32_t capacity, const spring_case* c) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  uint32_t n, pair_count = 0, far = 0;
  uint32_t* pairs = NULL;
  uint32_t before = c->late_block ? 5u : 0u;
  sph_mpi_counts counts;
  springs_def(&def, capacity);
  def.integrator = c->integrator;
  def.solver = c->solver;
  n = make_worlds(context, &def, column_min, column_max, c->stir, &single, &world, &single_tank, &tank);
  (void)single_tank;
  (void)tank;
  set_springs(world, c);
  if (c->sink) mpi_test_add_top_sink(world);
  if (g_rank == 0) {
    uint32_t* ids = NULL;
    float* x = NULL;
    float* v = NULL;
    const uint32_t m = read_in_id_order(single, &ids, &x, &v);
    REQUIRE(m == n, "the column");
    pairs = linked_pairs(x, n, &pair_count);
    set_springs(single, c);
    if (c->sink) mpi_test_add_top_sink(single);
    free(ids);
    free(x);
    free(v);
  }
  if (before) {
    if (g_rank == 0) mpi_test_step(single, before, 0);
    mpi_test_step(world, before, 1);
    /* A block [0.25, 0.33] x [0, 0.08] x [0, 0.06], added by the last rank. */
    mpi_test_add_block(single, world, (sph_vec3){0.25f, 0.0f, 0.0f}, (sph_vec3){0.33f, 0.08f, 0.06f},
                       g_size - 1, &n);
  }
  if (g_rank == 0) mpi_test_step(single, c->substeps - before, 0);
  mpi_test_step(world, c->substeps - before, 1);

  REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK, "counts init");
  REQUIRE(sph_mpi_world_get_counts(world, &counts) == SPH_OK, "counts");
  CHECK(g_size == 1 || counts.migrated > 0, "%s: no particle migrated", c->name);
  CHECK(c->sink || counts.global_count == n, "%s: %llu particles, %u added", c->name,
        (unsigned long long)counts.global_count, n);
  expect_same_particles(single, world, c->name);
  if (g_rank == 0) {
    far = far_pairs(single, pairs, pair_count, counts.axis);
    CHECK(!c->want_far || far > 0,
          "%s: no spring spans two cell layers: the case does not reach past the halo", c->name);
    printf(
        "%s: %u springs linked at the start (the column's), %u of them two or more cell layers long along "
        "%c\n",
        c->name, pair_count, far, "xyz"[counts.axis]);
  }
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
  free(pairs);
}

/* Rank checkpoints with springs (their lists name partners by id): the elastic stirred column saved
 * after 10 substeps, stepped 10 more live, restored into the world and loaded as a new world on
 * every rank, and loaded on rank 0 alone (another rank count, whose rank joins every saved file):
 * each, stepped 10 substeps more, equals the undivided world stepped 20, bit for bit. */
static void check_checkpoint(sph_context* context, uint32_t capacity) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  const spring_case c = {
      "checkpoint",     2.0f, 1e4f, 20.0f, 0.0f, 0.1f, 0, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
      SPH_SOLVER_WCSPH, 20,   0};
  char path[128];
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_world* loaded = NULL;
  sph_collider_id single_tank, tank;
  MPI_Comm alone;
  run_checkpoint_path(path, sizeof path, "mpi_springs_checkpoint");
  springs_def(&def, capacity);
  make_worlds(context, &def, column_min, column_max, c.stir, &single, &world, &single_tank, &tank);
  set_springs(world, &c);
  if (g_rank == 0) {
    set_springs(single, &c);
    mpi_test_step(single, 20, 0);
  }
  mpi_test_step(world, 10, 1);
  REQUIRE(sph_mpi_world_save_file(world, path) == SPH_OK, "save: %s", sph_get_last_error());
  mpi_test_step(world, 10, 1);
  expect_same_particles(single, world, "springs: the live world after a save");
  REQUIRE(sph_mpi_world_restore_file(world, path) == SPH_OK, "restore: %s", sph_get_last_error());
  mpi_test_step(world, 10, 1);
  expect_same_particles(single, world, "springs: restored");
  REQUIRE(sph_mpi_world_load_file(context, MPI_TEST_COMM, path, &loaded) == SPH_OK, "load: %s",
          sph_get_last_error());
  mpi_test_step(loaded, 10, 1);
  expect_same_particles(single, loaded, "springs: loaded");
  REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");
  /* Rank 0 alone takes every rank's file: springs whose ends were saved on two ranks join. */
  MPI_Comm_split(MPI_COMM_WORLD, g_rank == 0 ? 0 : MPI_UNDEFINED, g_rank, &alone);
  if (g_rank == 0) {
    uint32_t* want_id = NULL;
    float *want_x = NULL, *want_v = NULL, *got_x = NULL, *got_v = NULL;
    double worst = 0.0;
    uint32_t m, differ;
    loaded = NULL;
    REQUIRE(sph_mpi_world_load_file(context, (int32_t)MPI_Comm_c2f(alone), path, &loaded) == SPH_OK,
            "load on one rank: %s", sph_get_last_error());
    mpi_test_step(loaded, 10, 1);
    m = read_in_id_order(single, &want_id, &want_x, &want_v);
    mpi_test_gather_on(loaded, alone, m, &got_x, &got_v);
    differ = mpi_differ(got_x, got_v, want_x, want_v, m, &worst);
    CHECK(differ == 0, "springs: saved on %d ranks, loaded on 1: %u of %u particles differ", g_size, differ,
          m);
    printf("springs: saved on %d ranks, loaded on 1: %u particles, %u differ\n", g_size, m, differ);
    REQUIRE(sph_world_destroy(loaded) == SPH_OK, "destroy");
    MPI_Comm_free(&alone);
    free(want_id);
    free(want_x);
    free(want_v);
    free(got_x);
    free(got_v);
  }
  remove_saved_set(path);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
}

/* This rank's file of the set saved at `path` (malloc'd, *size bytes). */
static unsigned char* read_rank_file(const char* path, long* size) {
  char name[512];
  unsigned char* bytes = NULL;
  FILE* f;
  *size = 0;
  REQUIRE(mpi_test_rank_file(path, g_rank, name, sizeof name), "the manifest %s", path);
  f = fopen(name, "rb");
  REQUIRE(f != NULL, "open %s", name);
  fseek(f, 0, SEEK_END);
  *size = ftell(f);
  fseek(f, 0, SEEK_SET);
  bytes = (unsigned char*)malloc((size_t)*size + 1u);
  REQUIRE(bytes != NULL && fread(bytes, 1, (size_t)*size, f) == (size_t)*size, "read %s", name);
  fclose(f);
  return bytes;
}

/* An add refused on one rank undoes the others' (sph_mpi_world_add_particles: no rank adds any),
 * and leaves each rank's world as it was: before, the ranks that had appended a particle kept the
 * springs' lowest waiting id lowered to its id (and the max speed recomputed from the velocities
 * left), so each rank saved other bytes than before the add. Here the save after the refused add
 * equals the save before it, file for file, on every rank. */
static void check_refused_add(sph_context* context, uint32_t capacity) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  const spring_case c = {
      "refused add",    2.0f, 1e4f, 20.0f, 0.0f, 0.1f, 0, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
      SPH_SOLVER_WCSPH, 5,    0};
  const float good[3] = {0.05f, 0.1f, 0.03f}, bad[3] = {NAN, 0.1f, 0.03f};
  long size_before = 0, size_after = 0;
  char path[128];
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  unsigned char *before, *after;
  sph_result r;
  run_checkpoint_path(path, sizeof path, "mpi_springs_refused_add");
  springs_def(&def, capacity);
  make_worlds(context, &def, column_min, column_max, c.stir, &single, &world, &single_tank, &tank);
  set_springs(world, &c);
  mpi_test_step(world, c.substeps, 1); /* every particle has made its springs */
  REQUIRE(sph_mpi_world_save_file(world, path) == SPH_OK, "save: %s", sph_get_last_error());
  before = read_rank_file(path, &size_before);
  r = sph_mpi_world_add_particles(world, g_rank == g_size - 1 ? bad : good, NULL, 1, NULL);
  CHECK(r == SPH_ERROR_INVALID_ARGUMENT, "springs: a NaN on the last rank refuses the add: %d", (int)r);
  if (g_rank != g_size - 1) { /* the others' message names the refusing rank */
    char expected[64];
    snprintf(expected, sizeof expected, "rank %d's particles were refused", g_size - 1);
    CHECK(strstr(sph_get_last_error(), expected) != NULL, "the refused add's message: %s",
          sph_get_last_error());
  }
  REQUIRE(sph_mpi_world_save_file(world, path) == SPH_OK, "save: %s", sph_get_last_error());
  after = read_rank_file(path, &size_after);
  CHECK(size_after == size_before && memcmp(before, after, (size_t)size_before) == 0,
        "springs: rank %d saves other bytes after a refused add (%ld against %ld)", g_rank, size_after,
        size_before);
  free(before);
  free(after);
  remove_saved_set(path);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
}

void mpi_springs_cases(sph_context* context, uint32_t capacity) {
  const spring_case cases[] = {
      {"elastic springs", 2.0f, 1e4f, 20.0f, 0.0f, 0.1f, 0, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_WCSPH, 20, 0},
      {"weak elastic springs", 4.0f, 100.0f, 0.0f, 0.0f, 0.1f, 0, 0, 1, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_WCSPH, 30, 0},
      {"plastic springs", 2.0f, 1e4f, 0.0f, 200.0f, 0.05f, 0, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_WCSPH, 20, 0},
      {"springs and a sink", 2.0f, 1e4f, 0.0f, 0.0f, 0.1f, 1, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_WCSPH, 20, 0},
      {"springs and a late block", 2.0f, 1e4f, 0.0f, 0.0f, 0.1f, 0, 1, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_WCSPH, 20, 0},
      {"RK4 springs", 2.0f, 1e4f, 20.0f, 0.0f, 0.1f, 0, 0, 0, SPH_INTEGRATOR_RK4, SPH_SOLVER_WCSPH, 12, 0},
      {"DFSPH springs", 2.0f, 1e4f, 20.0f, 0.0f, 0.1f, 0, 0, 0, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_DFSPH, 12, 0},
      {"DFSPH CG weak springs", 4.0f, 100.0f, 0.0f, 0.0f, 0.1f, 0, 0, 1, SPH_INTEGRATOR_SYMPLECTIC_EULER,
       SPH_SOLVER_DFSPH, 30, SPH_DFSPH_CONJUGATE_GRADIENTS},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) run_case(context, capacity, &cases[k]);
  check_checkpoint(context, capacity);
  check_refused_add(context, capacity);
}
