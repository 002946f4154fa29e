/* SPDX-License-Identifier: MIT */
/* The two-rank calibration of docs/scaling.md's model on the CPU backend (issue 19 item 6):
 *
 *   mpirun -np R bench/mpi_halo [--spacing S] [--substeps K] [--backend cpu|cuda] [--springs 1]
 *                               [--workers W] [--wait-barriers 1] [--solver wcsph|dfsph]
 *                               [--dfsph-solver jacobi|cg|chebyshev]
 *
 * --solver dfsph: the world steps DFSPH (the library's default bounds) instead of the weakly
 * compressible scheme; its solves' iterations over the timed step are printed, since a DFSPH
 * substep's cost is mostly theirs (each iteration two neighbour passes and two halo shares).
 * --dfsph-solver: its density solve's linear solver (sph_dfsph_params.linear_solver; default the
 * library's, Jacobi); cg's rank solve is host-driven with its own exchanges (a ghost's search
 * direction and velocity step each iteration), so it is timed apart.
 * --backend cuda: every rank on the CUDA backend (the host-staged halo path; ranks on one GPU
 * share it), the GPU calibration of the model. --springs 1: with SPH_FEATURE_SPRINGS (every
 * particle linked to its lattice neighbours in the warm-up frame; springs across ranks, on CPU
 * ranks and, since session 17, CUDA ranks), the cost of their exchanges and spring ghosts.
 * --workers W: each CPU rank's worker threads (sph_context_def.cpu_worker_count; default 0, all
 * hardware threads, which oversubscribes a machine as soon as two ranks share it).
 * A water block of 0.8 x 0.4 x 0.2 m at rest in a closed tank (the slabs cut its 0.8 m axis),
 * stepped one warm-up frame (the first cut and its migration) and then timed over K substeps
 * (default 20). Prints, on rank 0: the ranks, the particles per rank, the ghosts (halo) per rank
 * in the last substep against the model's slab halo (per face beside another slab, one support
 * radius of the block and the part of the slab's end layer its neighbour owns: (1 + that part)
 * h / L of its particles), ms per substep (the slowest
 * rank, MPI_Wtime around the step) and the step's stage times; each stage split into the time
 * inside the transport's MPI calls (the wait there for the slowest rank and the transfer) and
 * the rest (the rank's own work: packing, sorting, gathering ghosts, computing), on rank 0 and
 * as the largest and smallest over the ranks, then each rank's row (owned particles, ghosts, slab,
 * mean neighbours, its force, density and hash+sort stages; whether a slow rank holds more work or
 * runs it slower), with the transport's calls over the step
 * (mpi_halo_transport.h; issue 19; the CPU backend splits its stages so, CUDA ranks show their
 * transport time only as the step's total, outside the stages); and a ping-pong of MPI messages of 8 B to 8
 * MB between ranks 0 and 1 (their latency and bandwidth, the model's alpha and beta for this host's MPI).
 * --wait-barriers 1: each transport call waits at a timed MPI_Barrier first, so the split tells
 * the wait for the slowest rank (the barrier) from the transfer (the call after it); the
 * barriers cost a latency a call, so the substep time is not the default run's. */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_halo_transport.h"
#include "sph_c.h"
#include "sph_mpi.h"
#include "support.h"

/* Per rank, over the timed step: each stage's time, its transport share, that share's barrier
 * waits and the rest; then the transport inside and outside the stages. */
enum { kStageRows = 4, kSplitValues = kStageRows * SPH_STAGE_COUNT + 2 };

static void print_row(const char* label, const double* v) {
  printf("  %-34s", label);
  for (int s = 0; s < SPH_STAGE_COUNT; ++s) printf(" %11.2f", v[s]);
  printf("\n");
}

/* Rank 0 prints the split of the timed step: `before` and `after` are this rank's transport
 * times around it, `stats` its stage times. Collective (two reductions). */
static void print_split(int rank, int wait_barriers, const sph_stats* stats, const mpi_halo_transport* before,
                        const mpi_halo_transport* after) {
  double mine[kSplitValues], hi[kSplitValues], lo[kSplitValues];
  double calls_ms[MPI_HALO_CALL_COUNT], calls_hi[MPI_HALO_CALL_COUNT];
  double inside = 0.0;
  for (int s = 0; s < SPH_STAGE_COUNT; ++s) {
    mine[s] = stats->stage_ms[s];
    mine[SPH_STAGE_COUNT + s] = after->stage_ms[s];
    mine[2 * SPH_STAGE_COUNT + s] = after->stage_wait_ms[s];
    mine[3 * SPH_STAGE_COUNT + s] = stats->stage_ms[s] - after->stage_ms[s];
    inside += after->stage_ms[s];
  }
  mine[kSplitValues - 2] = after->total_ms - before->total_ms; /* the step's transport */
  mine[kSplitValues - 1] = mine[kSplitValues - 2] - inside;    /* of it, outside the stages */
  for (int c = 0; c < MPI_HALO_CALL_COUNT; ++c) calls_ms[c] = after->ms[c] - before->ms[c];
  MPI_Reduce(mine, hi, kSplitValues, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(mine, lo, kSplitValues, MPI_DOUBLE, MPI_MIN, 0, MPI_COMM_WORLD);
  MPI_Reduce(calls_ms, calls_hi, MPI_HALO_CALL_COUNT, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  printf("stage ms over the step, split (transport: inside its MPI calls)\n  %-34s", "");
  for (int s = 0; s < SPH_STAGE_COUNT; ++s) printf(" %11s", support_stage_name(s));
  printf("\n");
  print_row("rank 0 stage", mine);
  print_row("rank 0 transport", mine + SPH_STAGE_COUNT);
  if (wait_barriers) print_row("rank 0 of which barrier wait", mine + 2 * SPH_STAGE_COUNT);
  print_row("rank 0 rest", mine + 3 * SPH_STAGE_COUNT);
  print_row("max over ranks: stage", hi);
  print_row("max over ranks: transport", hi + SPH_STAGE_COUNT);
  if (wait_barriers) print_row("max over ranks: barrier wait", hi + 2 * SPH_STAGE_COUNT);
  print_row("max over ranks: rest", hi + 3 * SPH_STAGE_COUNT);
  print_row("min over ranks: transport", lo + SPH_STAGE_COUNT);
  print_row("min over ranks: rest", lo + 3 * SPH_STAGE_COUNT);
  printf("transport ms over the step: rank 0 %.2f (%.2f outside the stages), max over ranks %.2f, min %.2f\n",
         mine[kSplitValues - 2], mine[kSplitValues - 1], hi[kSplitValues - 2], lo[kSplitValues - 2]);
  printf("transport calls over the step (rank 0: calls, ms; max ms over ranks):");
  for (int c = 0; c < MPI_HALO_CALL_COUNT; ++c)
    if (after->calls[c] > before->calls[c])
      printf(" %s %llu %.2f (%.2f)", mpi_halo_call_name(c),
             (unsigned long long)(after->calls[c] - before->calls[c]), calls_ms[c], calls_hi[c]);
  printf("\n");
}

/* Rank 0 prints every rank's particles, ghosts, slab, mean neighbours and its compute and exchange
 * stages (ms over the timed step; transport: inside its MPI calls): whether a slow rank holds
 * more work or runs it slower. Collective (one gather). */
enum { kRankValues = 9 };
static void print_ranks(int rank, int size, const sph_mpi_counts* c, const sph_stats* stats,
                        const mpi_halo_transport* t) {
  const double mine[kRankValues] = {(double)c->local_count,
                                    (double)c->local_ghosts,
                                    (double)c->slab_first,
                                    (double)c->slab_last,
                                    (double)stats->neighbors_mean,
                                    stats->stage_ms[SPH_STAGE_FORCES],
                                    stats->stage_ms[SPH_STAGE_DENSITY],
                                    stats->stage_ms[SPH_STAGE_HASH_SORT],
                                    t->stage_ms[SPH_STAGE_DENSITY] + t->stage_ms[SPH_STAGE_HASH_SORT]};
  double* all = rank == 0 ? (double*)malloc(sizeof(double) * kRankValues * (size_t)size) : NULL;
  if (rank == 0 && !all) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Gather(mine, kRankValues, MPI_DOUBLE, all, kRankValues, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  printf(
      "per rank: owned, ghosts, slab layers, mean neighbours, forces ms, its us a particle over the step, "
      "density ms, "
      "hash+sort ms, their transport ms\n");
  for (int r = 0; r < size; ++r) {
    const double* v = all + (size_t)r * kRankValues;
    printf("  rank %2d %7.0f %6.0f [%4.0f, %4.0f] %6.2f %8.2f %6.3f %8.2f %8.2f %8.2f\n", r, v[0], v[1], v[2],
           v[3], v[4], v[5], v[0] > 0 ? 1e3 * v[5] / v[0] : 0.0, v[6], v[7], v[8]);
  }
  free(all);
}

/* Rank 0 prints every rank's hash+sort stage in its parts over the timed step (ms, transport
 * included; src/core/distributed.h's HaloPhase): where a many-rank host's hash+sort goes. */
static void print_phases(int rank, int size, const mpi_halo_transport* before,
                         const mpi_halo_transport* after) {
  double mine[MPI_HALO_PHASE_COUNT];
  for (int p = 0; p < MPI_HALO_PHASE_COUNT; ++p) mine[p] = after->phase_ms[p] - before->phase_ms[p];
  double* all = rank == 0 ? (double*)malloc(sizeof(double) * MPI_HALO_PHASE_COUNT * (size_t)size) : NULL;
  if (rank == 0 && !all) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Gather(mine, MPI_HALO_PHASE_COUNT, MPI_DOUBLE, all, MPI_HALO_PHASE_COUNT, MPI_DOUBLE, 0,
             MPI_COMM_WORLD);
  if (rank != 0) return;
  printf("hash+sort in parts per rank, ms over the step (transport included):");
  for (int p = 0; p < MPI_HALO_PHASE_COUNT; ++p) printf(" %s", mpi_halo_phase_name(p));
  printf("\n");
  for (int r = 0; r < size; ++r) {
    printf("  rank %2d", r);
    for (int p = 0; p < MPI_HALO_PHASE_COUNT; ++p)
      printf(" %8.2f", all[(size_t)r * MPI_HALO_PHASE_COUNT + p]);
    printf("\n");
  }
  free(all);
}

static void need(sph_result r, const char* what) {
  if (r != SPH_OK) {
    fprintf(stderr, "mpi_halo: %s: %d %s\n", what, (int)r, sph_get_last_error());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
}

static void ping_pong(int rank) {
  static const size_t kSizes[] = {8, 1024, 65536, 131072, 1u << 20, 8u << 20};
  char* buf = (char*)calloc(8u << 20, 1);
  if (!buf) MPI_Abort(MPI_COMM_WORLD, 1);
  for (size_t k = 0; k < sizeof kSizes / sizeof kSizes[0]; ++k) {
    const int n = (int)kSizes[k];
    const int reps = n > 65536 ? 20 : 2000;
    double t0;
    MPI_Barrier(MPI_COMM_WORLD);
    t0 = MPI_Wtime();
    for (int i = 0; i < reps; ++i) {
      if (rank == 0) {
        MPI_Send(buf, n, MPI_CHAR, 1, 0, MPI_COMM_WORLD);
        MPI_Recv(buf, n, MPI_CHAR, 1, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      } else if (rank == 1) {
        MPI_Recv(buf, n, MPI_CHAR, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        MPI_Send(buf, n, MPI_CHAR, 0, 0, MPI_COMM_WORLD);
      }
    }
    if (rank == 0) {
      const double one_way = (MPI_Wtime() - t0) / (2.0 * reps);
      printf("ping-pong %8d B: %9.2f us one way, %8.3f GB/s\n", n, one_way * 1e6, n / one_way * 1e-9);
    }
  }
  free(buf);
}

int main(int argc, char** argv) {
  float spacing = 0.01f;
  uint32_t substeps = 20;
  sph_backend backend = SPH_BACKEND_CPU;
  int springs = 0;
  uint32_t workers = 0;
  int wait_barriers = 0;
  sph_solver solver = SPH_SOLVER_WCSPH;
  uint32_t linear_solver = 0; /* sph_dfsph_params.linear_solver; 0: the library's default */
  mpi_halo_transport before, after;
  int rank, size;
  sph_context* context = NULL;
  sph_world* scratch = NULL;
  sph_world* world = NULL;
  sph_world_def def;
  sph_world_params params;
  sph_mpi_counts c;
  sph_stats stats;
  float* positions = NULL;
  uint32_t n = 0;
  double t0, mine, slowest;
  int64_t owned_max;
  double model_sum = 0.0;
  const support_tank tank = {{0.0f, 0.3f, 0.0f}, {0.45f, 0.3f, 0.15f}, 0.01f, 0.0f};
  const sph_vec3 lo = {-0.4f, 0.0f, -0.1f}, hi = {0.4f, 0.4f, 0.1f};
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  for (int i = 1; i + 1 < argc; i += 2) {
    if (strcmp(argv[i], "--spacing") == 0) spacing = (float)atof(argv[i + 1]);
    if (strcmp(argv[i], "--substeps") == 0) substeps = (uint32_t)atoi(argv[i + 1]);
    if (strcmp(argv[i], "--backend") == 0) backend = support_backend_from_name(argv[i + 1], SPH_BACKEND_CPU);
    if (strcmp(argv[i], "--springs") == 0) springs = atoi(argv[i + 1]) != 0;
    if (strcmp(argv[i], "--workers") == 0) workers = (uint32_t)atoi(argv[i + 1]);
    if (strcmp(argv[i], "--wait-barriers") == 0) wait_barriers = atoi(argv[i + 1]) != 0;
    if (strcmp(argv[i], "--solver") == 0) {
      if (strcmp(argv[i + 1], "dfsph") == 0) {
        solver = SPH_SOLVER_DFSPH;
      } else if (strcmp(argv[i + 1], "wcsph") != 0) {
        if (rank == 0) fprintf(stderr, "mpi_halo: --solver takes wcsph or dfsph, not %s\n", argv[i + 1]);
        MPI_Finalize();
        return 2;
      }
    }
    if (strcmp(argv[i], "--dfsph-solver") == 0) {
      const char* name = argv[i + 1];
      linear_solver = strcmp(name, "jacobi") == 0      ? SPH_DFSPH_JACOBI
                      : strcmp(name, "cg") == 0        ? SPH_DFSPH_CONJUGATE_GRADIENTS
                      : strcmp(name, "chebyshev") == 0 ? SPH_DFSPH_CHEBYSHEV
                                                       : 0u;
      if (linear_solver == 0u) {
        if (rank == 0)
          fprintf(stderr, "mpi_halo: --dfsph-solver takes jacobi, cg or chebyshev, not %s\n", name);
        MPI_Finalize();
        return 2;
      }
    }
  }
  if (linear_solver != 0u && solver != SPH_SOLVER_DFSPH) {
    if (rank == 0) fprintf(stderr, "mpi_halo: --dfsph-solver needs --solver dfsph\n");
    MPI_Finalize();
    return 2;
  }
  {
    sph_context_def context_def;
    need(support_context_def_init(backend, &context_def), "context def");
    context_def.cpu_worker_count = workers;
    need(sph_context_create(&context_def, &context), "context");
  }
  need(sph_world_def_init(&def), "def");
  def.particle_spacing = spacing;
  def.kernel_radius = 1.8f * spacing;
  if (springs) def.features |= SPH_FEATURE_SPRINGS;
  def.solver = solver;
  /* The block holds about sqrt 2 (0.8 x 0.4 x 0.2 m) / spacing^3 particles (the FCC lattice);
   * room for all of them on any rank, at least 2^20. */
  {
    const double block = 1.4143 * 0.8 * 0.4 * 0.2 / ((double)spacing * spacing * spacing);
    def.capacity = block * 1.25 > (double)(1u << 20) ? (uint32_t)(block * 1.25) : 1u << 20;
  }
  if (rank == 0) {
    /* The block filled on a scratch undivided world, its particles added from rank 0. */
    need(sph_world_create(context, &def, &scratch), "scratch world");
    need(support_dam_break(context, scratch, &tank, lo, hi, NULL, NULL, &n), "block");
    need(support_copy_by_id(scratch, SPH_ATTRIBUTE_POSITION, (void**)&positions, &n), "positions");
    sph_world_destroy(scratch);
  }
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  need(sph_mpi_world_create(context, &def, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD), NULL, &world), "world");
  need(support_tank_create(context, world, &tank, NULL, NULL), "tank");
  need(sph_mpi_world_add_particles(world, positions, NULL, rank == 0 ? n : 0, NULL), "particles");
  free(positions);
  need(support_params_gravity_and_steps(&params, 0.0f, -9.81f, 0.0f, 1e-5f, 1e-3f), "params");
  params.max_substeps = 2;
  need(sph_world_set_params(world, &params), "set params");
  if (linear_solver != 0u) {
    sph_dfsph_params dfsph;
    need(sph_dfsph_params_init(&dfsph), "dfsph params init");
    need(sph_world_get_dfsph_params(world, &dfsph), "dfsph params");
    dfsph.linear_solver = linear_solver;
    need(sph_world_set_dfsph_params(world, &dfsph), "set dfsph params");
  }
  sph_mpi_world_step(world, 1.0f); /* warm-up: the first cut and its migration */
  params.max_substeps = substeps;
  need(sph_world_set_params(world, &params), "set params");
  /* Every rank turns the barriers on before the same (timed) step. */
  if (wait_barriers && mpi_halo_wait_at_barriers(world) != 0) MPI_Abort(MPI_COMM_WORLD, 1);
  if (mpi_halo_transport_read(world, &before) != 0) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = MPI_Wtime();
  sph_mpi_world_step(world, 1.0f);
  mine = MPI_Wtime() - t0;
  if (mpi_halo_transport_read(world, &after) != 0) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Reduce(&mine, &slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  need(sph_mpi_counts_init(&c), "counts init");
  need(sph_mpi_world_get_counts(world, &c), "counts");
  need(sph_stats_init(&stats), "stats init");
  need(sph_world_get_stats(world, &stats), "stats");
  owned_max = c.local_count;
  MPI_Allreduce(MPI_IN_PLACE, &owned_max, 1, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
  {
    /* docs/scaling.md's slab halo: each face beside another slab takes the layer beyond it and
     * the part of its own end layer the slab leaves to its neighbour (cuts between sixteenths of
     * a layer, src/core/slab_rules.h): (1 + that part) h / L of the block's particles per face
     * (L = 0.8 m, the cut axis); at whole-layer cuts h / L a face, 2 (R - 1) faces. */
    const double h = 1.8 * spacing, per_layer = n * h / 0.8;
    double layers = 0.0;
    if (c.local_count > 0 && c.slab_sub_first != INT32_MIN)
      layers += 1.0 + (double)(((c.slab_sub_first % 16) + 16) % 16) / 16.0;
    if (c.local_count > 0 && c.slab_sub_last != INT32_MAX)
      layers += 1.0 + (double)(15 - ((c.slab_sub_last % 16) + 16) % 16) / 16.0;
    model_sum = layers * per_layer;
    MPI_Allreduce(MPI_IN_PLACE, &model_sum, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  }
  if (rank == 0) {
    const double model = model_sum / size;
    printf("backend %s%s, %s, workers a rank %u (0: all hardware threads)%s\n",
           backend == SPH_BACKEND_CUDA ? "cuda" : "cpu", springs ? ", springs" : "",
           solver != SPH_SOLVER_DFSPH                       ? "WCSPH"
           : linear_solver == SPH_DFSPH_CONJUGATE_GRADIENTS ? "DFSPH (conjugate gradients)"
           : linear_solver == SPH_DFSPH_CHEBYSHEV           ? "DFSPH (Chebyshev)"
                                                            : "DFSPH",
           workers, wait_barriers ? ", a timed barrier before each transport call" : "");
    printf("ranks %d, %u particles (%.0f per rank, the fullest %lld), %u substeps\n", size, n,
           (double)n / size, (long long)owned_max, stats.substeps);
    printf(
        "ghosts per rank (last substep): %.0f measured, %.0f model ((1 + the end layer's share left to the "
        "neighbour) h / L per slab face, h = 1.8 spacings)\n",
        (double)c.global_ghosts / size, model);
    printf("ms per substep (slowest rank): %.3f\n", 1e3 * slowest / stats.substeps);
    if (solver == SPH_SOLVER_DFSPH)
      printf("DFSPH iterations a substep: density %.2f, divergence %.2f\n",
             (double)stats.pressure_iterations / stats.substeps,
             (double)stats.divergence_iterations / stats.substeps);
    printf("rank 0 stage ms over the step:");
    for (int s = 0; s < SPH_STAGE_COUNT; ++s) printf(" %.1f", stats.stage_ms[s]);
    printf("\n");
  }
  print_split(rank, wait_barriers, &stats, &before, &after);
  print_ranks(rank, size, &c, &stats, &after);
  print_phases(rank, size, &before, &after);
  sph_world_destroy(world);
  sph_context_destroy(context);
  if (size >= 2) ping_pong(rank);
  MPI_Finalize();
  return 0;
}
