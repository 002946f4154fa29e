/* SPDX-License-Identifier: MIT */
#include "mpi_test_world.h"

#include <stdlib.h>
#include <string.h>

#include "support.h"

int g_rank = 0, g_size = 1, g_failures = 0;

static const support_tank kTank = {{0.2f, 0.1f, 0.03f}, {0.2f, 0.1f, 0.03f}, 0.005f, 0.0f};

void mpi_test_init(int* argc, char*** argv, sph_context** context) {
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  REQUIRE(support_context_create(SPH_BACKEND_CPU, context) == SPH_OK, "context");
}

int mpi_test_finish(sph_context* context, const char* name) {
  int total = 0;
  REQUIRE(sph_context_destroy(context) == SPH_OK, "context destroy");
  MPI_Allreduce(&g_failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (g_rank == 0)
    printf("%s %s: %d failures over %d ranks\n", total == 0 ? "PASS" : "FAIL", name, total, g_size);
  MPI_Finalize();
  return total == 0 ? 0 : 1;
}

void mpi_test_world_def(sph_world_def* def) {
  REQUIRE(sph_world_def_init(def) == SPH_OK, "def init");
  def->features = SPH_FEATURE_NONE;
  def->capacity = 4096;
  def->particle_spacing = MPI_TEST_SPACING;
  def->kernel_radius = 1.8f * MPI_TEST_SPACING;
}

void mpi_test_dam(sph_context* context, const sph_world_def* def, float stir,
                  const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n) {
  mpi_test_dam_on(context, def, stir, MPI_COMM_WORLD, mpi_def, single, world, n);
}

void mpi_test_dam_on(sph_context* context, const sph_world_def* def, float stir, MPI_Comm comm,
                     const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n) {
  int rank = 0;
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_world* one = NULL;
  float* positions = NULL;
  float* velocities = NULL;
  *n = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    REQUIRE(sph_world_create(context, def, &one) == SPH_OK, "single world");
    REQUIRE(support_dam_break(context, one, &kTank, column_min, column_max, NULL, NULL, n) == SPH_OK, "dam");
    REQUIRE(support_copy_by_id(one, SPH_ATTRIBUTE_POSITION, (void**)&positions, n) == SPH_OK, "positions");
    velocities = (float*)calloc(3 * (size_t)*n + 3, sizeof(float));
    REQUIRE(velocities != NULL, "calloc");
    if (stir > 0.0f) {
      uint64_t state = 12345;
      support_random_velocities(velocities, *n, stir, NULL, &state);
      REQUIRE(
          sph_world_set_attribute(one, SPH_ATTRIBUTE_VELOCITY, velocities, 12ull * *n, 12, 0, *n) == SPH_OK,
          "stir");
    }
  }
  MPI_Bcast(n, 1, MPI_UINT32_T, 0, comm);
  REQUIRE(sph_mpi_world_create(context, def, (int32_t)MPI_Comm_c2f(comm), mpi_def, world) == SPH_OK,
          "distributed world");
  REQUIRE(support_tank_create(context, *world, &kTank, NULL, NULL) == SPH_OK, "tank");
  REQUIRE(sph_mpi_world_add_particles(*world, positions, velocities, rank == 0 ? *n : 0, NULL) == SPH_OK,
          "add particles");
  free(positions);
  free(velocities);
  if (single)
    *single = one;
  else if (one)
    sph_world_destroy(one);
}

void mpi_test_step(sph_world* world, uint32_t substeps, int distributed) {
  sph_world_params p;
  sph_stats stats;
  sph_result r;
  REQUIRE(support_params_gravity_and_steps(&p, 0.0f, -9.81f, 0.0f, 1e-5f, 1e-3f) == SPH_OK, "params");
  p.max_substeps = substeps;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
  r = distributed ? sph_mpi_world_step(world, 1.0f) : sph_world_step(world, 1.0f);
  CHECK(r == SPH_INCOMPLETE, "step: %d, expected SPH_INCOMPLETE after %u substeps", (int)r, substeps);
  REQUIRE(sph_stats_init(&stats) == SPH_OK, "stats init");
  REQUIRE(sph_world_get_stats(world, &stats) == SPH_OK, "stats");
  CHECK(stats.substeps == substeps, "%u substeps, expected %u", stats.substeps, substeps);
}

void mpi_test_gather(sph_world* world, uint32_t n, float** x, float** v) {
  mpi_test_gather_on(world, MPI_COMM_WORLD, n, x, v);
}

void mpi_test_gather_on(sph_world* world, MPI_Comm comm, uint32_t n, float** x, float** v) {
  uint64_t got = 0;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  *x = NULL;
  *v = NULL;
  if (rank == 0) {
    *x = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    *v = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    REQUIRE(*x && *v, "malloc");
  }
  REQUIRE(sph_mpi_world_gather(world, 0, *x, *v, NULL, n, &got) == SPH_OK, "gather");
  CHECK(rank != 0 || got == n, "gathered %llu of %u", (unsigned long long)got, n);
}

void mpi_test_read(sph_world* single, uint32_t n, float** x, float** v) {
  uint32_t m = 0;
  REQUIRE(support_copy_by_id(single, SPH_ATTRIBUTE_POSITION, (void**)x, &m) == SPH_OK && m == n, "read");
  REQUIRE(support_copy_by_id(single, SPH_ATTRIBUTE_VELOCITY, (void**)v, &m) == SPH_OK && m == n, "read");
}

/* Little-endian reads of the manifest (docs/checkpoint.md, "Distributed worlds"). */
static uint32_t manifest_u32(const unsigned char* p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int mpi_test_rank_file(const char* manifest, int rank, char* out, size_t size) {
  unsigned char buf[1 << 16];
  size_t n, at, k;
  uint32_t ranks;
  const char* slash;
  FILE* f = fopen(manifest, "rb");
  if (!f) return 0;
  n = fread(buf, 1, sizeof buf, f);
  fclose(f);
  /* magic 8, version 4, rank count 4, particles 8, rebalance 4, axis 4, cut 4, rebalances 4 */
  if (n < 40) return 0;
  ranks = manifest_u32(buf + 12);
  if (rank < 0 || (uint32_t)rank >= ranks) return 0;
  at = 40 + 4 * ((size_t)ranks - 1); /* the cuts */
  for (k = 0;; ++k) {
    uint32_t length;
    if (at + 36 > n) return 0;
    length = manifest_u32(buf + at + 32); /* after 4 u32 counters, the size and the hash */
    if (at + 36 + length > n) return 0;
    if (k == (size_t)rank) {
      const int dir = (slash = strrchr(manifest, '/')) ? (int)(slash - manifest + 1) : 0;
      return snprintf(out, size, "%.*s%.*s", dir, manifest, (int)length, (const char*)buf + at + 36) <
             (int)size;
    }
    at += 36 + length;
  }
}
