/* SPDX-License-Identifier: MIT */
#include "mpi_test_world.h"

#include <math.h>
#include <stddef.h>
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
  def->kernel_radius = MPI_TEST_KERNEL_RADIUS;
}

sph_context* mpi_test_cuda_context(uint32_t lanes) {
  sph_context_def cdef;
  sph_context* c = NULL;
  REQUIRE(sph_context_def_init(&cdef) == SPH_OK, "context def");
  cdef.backend = SPH_BACKEND_CUDA;
  cdef.cuda_particle_lanes = lanes;
  cdef.cuda_dfsph_masks = sph_test_cuda_dfsph_masks(); /* scripts/gpu-test: once more with lists */
  REQUIRE(sph_context_create(&cdef, &c) == SPH_OK, "CUDA context: %s", sph_get_last_error());
  return c;
}

void mpi_test_dam(sph_context* context, const sph_world_def* def, float stir,
                  const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n) {
  mpi_test_dam_on(context, def, stir, MPI_COMM_WORLD, mpi_def, single, world, n);
}

void mpi_test_make_worlds(sph_context* context, const sph_world_def* def, sph_vec3 column_min,
                          sph_vec3 column_max, float stir, MPI_Comm comm, const sph_mpi_world_def* mpi_def,
                          mpi_test_worlds* out) {
  int rank = 0;
  float* positions = NULL;
  float* velocities = NULL;
  memset(out, 0, sizeof *out);
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    REQUIRE(sph_world_create(context, def, &out->single) == SPH_OK, "single world");
    REQUIRE(support_dam_break(context, out->single, &kTank, column_min, column_max, NULL, &out->single_tank,
                              &out->n) == SPH_OK,
            "dam");
    REQUIRE(support_copy_by_id(out->single, SPH_ATTRIBUTE_POSITION, (void**)&positions, &out->n) == SPH_OK,
            "positions");
    velocities = (float*)calloc(3 * (size_t)out->n + 3, sizeof(float));
    REQUIRE(velocities != NULL, "calloc");
    if (stir > 0.0f) {
      uint64_t state = 12345;
      support_random_velocities(velocities, out->n, stir, NULL, &state);
      REQUIRE(sph_world_set_attribute(out->single, SPH_ATTRIBUTE_VELOCITY, velocities, 12ull * out->n, 12, 0,
                                      out->n) == SPH_OK,
              "stir");
    }
  }
  MPI_Bcast(&out->n, 1, MPI_UINT32_T, 0, comm);
  REQUIRE(sph_mpi_world_create(context, def, (int32_t)MPI_Comm_c2f(comm), mpi_def, &out->world) == SPH_OK,
          "distributed world");
  REQUIRE(support_tank_create(context, out->world, &kTank, NULL, &out->tank) == SPH_OK, "tank");
  REQUIRE(sph_mpi_world_add_particles(out->world, positions, velocities, rank == 0 ? out->n : 0,
                                      &out->first) == SPH_OK,
          "add particles");
  free(positions);
  free(velocities);
}

void mpi_test_dam_on(sph_context* context, const sph_world_def* def, float stir, MPI_Comm comm,
                     const sph_mpi_world_def* mpi_def, sph_world** single, sph_world** world, uint32_t* n) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  mpi_test_worlds w;
  mpi_test_make_worlds(context, def, column_min, column_max, stir, comm, mpi_def, &w);
  *world = w.world;
  *n = w.n;
  if (single)
    *single = w.single;
  else if (w.single)
    sph_world_destroy(w.single);
}

void mpi_test_step(sph_world* world, uint32_t substeps, int distributed) {
  sph_stats stats;
  mpi_test_step_stats(world, substeps, distributed, &stats);
}

void mpi_test_step_stats(sph_world* world, uint32_t substeps, int distributed, sph_stats* stats) {
  sph_world_params p;
  sph_result r;
  REQUIRE(support_params_gravity_and_steps(&p, 0.0f, -9.81f, 0.0f, 1e-5f, 1e-3f) == SPH_OK, "params");
  p.max_substeps = substeps;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
  r = distributed ? sph_mpi_world_step(world, 1.0f) : sph_world_step(world, 1.0f);
  CHECK(r == SPH_INCOMPLETE, "step: %d, expected SPH_INCOMPLETE after %u substeps", (int)r, substeps);
  REQUIRE(sph_stats_init(stats) == SPH_OK, "stats init");
  REQUIRE(sph_world_get_stats(world, stats) == SPH_OK, "stats");
  CHECK(stats->substeps == substeps, "%u substeps, expected %u", stats->substeps, substeps);
}

/* The solver fields of sph_stats, each 32 bits (a uint32_t count or a float). */
#define MPI_TEST_SOLVER_FIELD(field) \
  { #field, offsetof(sph_stats, field), sizeof(((const sph_stats*)0)->field) }
static const struct {
  const char* name;
  size_t offset, size;
} kSolverFields[] = {
    MPI_TEST_SOLVER_FIELD(pressure_iterations),    MPI_TEST_SOLVER_FIELD(pressure_iterations_max),
    MPI_TEST_SOLVER_FIELD(divergence_iterations),  MPI_TEST_SOLVER_FIELD(divergence_iterations_max),
    MPI_TEST_SOLVER_FIELD(density_error_mean),     MPI_TEST_SOLVER_FIELD(density_error_max),
    MPI_TEST_SOLVER_FIELD(divergence_error_mean),  MPI_TEST_SOLVER_FIELD(divergence_error_max),
    MPI_TEST_SOLVER_FIELD(pressure_solves_capped), MPI_TEST_SOLVER_FIELD(divergence_solves_capped),
    MPI_TEST_SOLVER_FIELD(density_error_largest),  MPI_TEST_SOLVER_FIELD(pressure_solves_guarded),
};
#undef MPI_TEST_SOLVER_FIELD
enum { kSolverFieldCount = sizeof kSolverFields / sizeof kSolverFields[0] };

const char* mpi_test_solver_stats_differ(const sph_stats* stats) {
  uint32_t bits[kSolverFieldCount], lowest[kSolverFieldCount], highest[kSolverFieldCount];
  for (size_t k = 0; k < kSolverFieldCount; ++k) {
    REQUIRE(kSolverFields[k].size == sizeof(uint32_t), "sph_stats.%s is not 32 bits", kSolverFields[k].name);
    memcpy(&bits[k], (const unsigned char*)stats + kSolverFields[k].offset, sizeof(uint32_t));
  }
  MPI_Allreduce(bits, lowest, kSolverFieldCount, MPI_UINT32_T, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(bits, highest, kSolverFieldCount, MPI_UINT32_T, MPI_MAX, MPI_COMM_WORLD);
  for (size_t k = 0; k < kSolverFieldCount; ++k)
    if (lowest[k] != highest[k]) return kSolverFields[k].name;
  return NULL;
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

void mpi_test_add_top_sink(sph_world* world) {
  sph_sink_def sink;
  sph_sink_id id;
  REQUIRE(sph_sink_def_init(&sink) == SPH_OK, "sink init");
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = -1.0f;
  sink.bounds_min.y = -1.0f;
  sink.bounds_min.z = -1.0f;
  sink.bounds_max.x = 1.0f;
  sink.bounds_max.y = 0.185f;
  sink.bounds_max.z = 1.0f;
  REQUIRE(sph_sink_create(world, &sink, &id) == SPH_OK, "sink: %s", sph_get_last_error());
}

void mpi_test_add_block(sph_world* single, sph_world* world, sph_vec3 lo, sph_vec3 hi, int adder,
                        uint32_t* n) {
  float* positions = NULL;
  uint32_t added = 0, total = 0;
  if (g_rank == 0) {
    sph_fill_box_desc box;
    REQUIRE(sph_fill_box_desc_init(&box) == SPH_OK, "fill init");
    box.min = lo;
    box.max = hi;
    REQUIRE(sph_world_fill_box(single, &box, &added) == SPH_OK, "fill");
    REQUIRE(support_copy_by_id(single, SPH_ATTRIBUTE_POSITION, (void**)&positions, &total) == SPH_OK, "read");
    REQUIRE(total == *n + added, "%u particles after the block", total);
  }
  MPI_Bcast(&added, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  if (adder != 0) { /* the adder takes rank 0's positions */
    if (g_rank != 0) {
      positions = (float*)malloc(sizeof(float) * 3 * ((size_t)*n + added + 1));
      REQUIRE(positions != NULL, "malloc");
    }
    MPI_Bcast(positions + 3 * (size_t)*n, (int)(3 * added), MPI_FLOAT, 0, MPI_COMM_WORLD);
  }
  REQUIRE(sph_mpi_world_add_particles(world, g_rank == adder ? positions + 3 * (size_t)*n : NULL, NULL,
                                      g_rank == adder ? added : 0, NULL) == SPH_OK,
          "rank %d adds the block", adder);
  *n += added;
  free(positions);
}

void mpi_test_add_probes(sph_world* world, sph_probe_id* point, sph_probe_id* gauge) {
  sph_probe_def def;
  REQUIRE(sph_probe_def_init(&def) == SPH_OK, "probe init");
  def.sampling = SPH_PROBE_EVERY_SUBSTEP;
  def.position.x = 0.05f;
  def.position.y = 0.02f;
  def.position.z = 0.03f;
  REQUIRE(sph_probe_create(world, &def, point) == SPH_OK, "point probe: %s", sph_get_last_error());
  def.kind = SPH_PROBE_GAUGE;
  def.position.x = 0.031f;
  def.position.y = -0.01f;
  def.position.z = 0.027f;
  def.length = 0.25f;
  REQUIRE(sph_probe_create(world, &def, gauge) == SPH_OK, "gauge: %s", sph_get_last_error());
}

uint32_t* mpi_test_removed_ids(sph_world* world, uint32_t* count, uint32_t* event_count) {
  uint32_t n = 0, events_n = 0;
  uint32_t* ids;
  sph_event events[8];
  REQUIRE(sph_world_get_removed_ids(world, NULL, 0, &n) == SPH_OK || n > 0, "removed ids count");
  ids = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
  REQUIRE(ids != NULL, "malloc");
  REQUIRE(sph_world_get_removed_ids(world, ids, n, count) == SPH_OK, "removed ids");
  REQUIRE(sph_world_get_events(world, events, 8, &events_n) == SPH_OK, "events");
  *event_count = 0;
  for (uint32_t i = 0; i < events_n && i < 8; ++i)
    if (events[i].type == SPH_EVENT_SINK_REMOVED) *event_count += events[i].count;
  return ids;
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

int32_t mpi_test_sub_layer(float x) {
  const float t = x * (1.0f / MPI_TEST_KERNEL_RADIUS);
  float j = floorf((t - floorf(t)) * 16.0f);
  j = j < 0.0f ? 0.0f : (j > 15.0f ? 15.0f : j);
  return 16 * (int32_t)floorf(t) + (int32_t)j;
}
