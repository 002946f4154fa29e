/* SPDX-License-Identifier: MIT */
/* The DFSPH solver and the RK4 integrator in a distributed world (docs/distributed.md) against one
 * undivided world, under mpirun on 1-4 ranks. RK4 sorts four times a substep: each stage gathers
 * its halo, and the stage's state (rk4_start, rk4_sum) moves with a particle that changes ranks
 * between stages. DFSPH: each solve iteration's neighbour passes read the ghosts' velocities
 * and pressure steps, which cross the halo after each pass, and its convergence test reads the
 * world's mean error, an exact sum over the ranks. Scenes: the dam break and the stirred
 * column (particles crossing the slab boundaries every few substeps), with the divergence solve
 * (the default) and without it, the stirred column with the Chebyshev density solve
 * (SPH_DFSPH_CHEBYSHEV: each particle's step mixed with its last one, which stays with the particle's
 * rank within the solve), and RK4's stirred column, 12 substeps each (frames of 7 and 5).
 * With the argument "cg" (ctest's mpi_solvers_cg_np1..3), DFSPH's density solve by conjugate
 * gradients (SPH_DFSPH_CONJUGATE_GRADIENTS, cpu_dfsph_cg.cpp), and its refusal on a rank whose walls
 * count in the density (SPH_FEATURE_BOUNDARY_DENSITY, as undivided):
 * each iteration's velocity update reads the ghosts' search directions p and its rate pass their
 * velocity steps dv_p, which cross the halo before each pass; its sums (value . z, p . A p, the
 * errors inside and outside the active set) are exact sums whose bins the ranks add, and the
 * restart rule's largest error outside the set and the largest error are maxima over the ranks.
 * Its scenes: a dam break twice as wide (2916 particles, 20 substeps: frames of 12 and 8), the
 * stirred column (12 substeps, 58 density iterations in the last 5), and the stirred column with a
 * cap of 4 iterations, which every solve of the last frame reaches (the capped substeps and events
 * checked against the undivided world's).
 * Checked:
 *   - the gathered particles equal the undivided world's bit for bit: every sum of a pass runs in
 *     the undivided world's order (the halo's sort keys), and the mean error is an exact sum
 *     (exact_float_sum.h) whose bins the ranks add (a solve that stopped one iteration apart
 *     would move every particle);
 *   - the solves' iteration counts, achieved mean and largest errors, capped substeps and guarded
 *     substeps (sph_stats) and the capped solves' events are the undivided world's; every solver field
 *     of the stats (mpi_test_solver_stats_differ) and the events are the same on every rank. The
 *     Chebyshev stirred column's guard (dfsph_chebyshev.h) turns one of its density solves to plain
 *     steps at these tight bounds (session 41: its mean error passed twice its smallest above the
 *     bound; 1 of 12 substeps on 1-4 ranks), so the ranks must turn the same solve at the same
 *     iteration on the world's errors; no other scene's solve may count one.
 * The bounds are 100 (density) and 10 (divergence) times tighter than the defaults (the divergence one set as
 * a share a step, 1e-4 at the 1 ms steps, so the division that turns it into a rate is part of what the ranks
 * must agree on), so the convergence test rather than the minimum ends the stirred column's solves (checked)
 * (19 density and 12 divergence iterations over the last 5 substeps). Without the velocities' or the pressure
 * steps' exchange, 1278-1404 of the 1404 particles differ on 2 ranks. The conjugate gradients' scenes,
 * measured with 20 substeps each on 2 ranks: without the search directions' exchange or without the velocity
 * steps', every particle differs (2916 of 2916, 1404 of 1404; without the velocity steps' the stirred column
 * takes 140 iterations in its first frame, not 125); with each rank's sums left unreduced, the ranks stop
 * their solves at different iterations and wait for each other in different collectives (the run hangs until
 * ctest's timeout). */
#include "mpi_compare.h"

static uint32_t g_features = SPH_FEATURE_NONE; /* the def's features ("walls": the walls' density) */

/* A scene: the column [0, column_max] in the tank, stirred at up to `stir` m/s. */
typedef struct scene {
  const char* name;
  float stir;
  sph_solver solver;
  sph_integrator integrator;
  uint32_t divergence_solve;
  uint32_t linear_solver;  /* DFSPH's density solve: SPH_DFSPH_JACOBI, _CONJUGATE_GRADIENTS or _CHEBYSHEV */
  uint32_t max_iterations; /* its cap (0: the default) */
  uint32_t expect_capped;  /* 1: the cap must be reached, 0: never, 2: not checked */
  float column_x;          /* the column's width, m */
  uint32_t frames[2];      /* substeps of the two frames */
  uint32_t expect_guarded; /* 1: some density solve must end in the Chebyshev guard's plain steps, 0: none */
} scene;

/* The capped density solves of the last step, from its events (every rank's, alike). */
static uint32_t capped_events(sph_world* world) {
  sph_event events[16];
  uint32_t n = 0, capped = 0;
  REQUIRE(sph_world_get_events(world, events, 16, &n) == SPH_OK, "events");
  for (uint32_t i = 0; i < n; ++i)
    if (events[i].type == SPH_EVENT_PRESSURE_SOLVE_CAPPED) capped += events[i].count;
  return capped;
}

static void run_scene(sph_context* context, const scene* sc) {
  const char* name = sc->name;
  const float stir = sc->stir;
  const sph_solver solver = sc->solver;
  const uint32_t divergence_solve = sc->divergence_solve;
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {sc->column_x, 0.2f, 0.06f};
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  uint32_t capped_total = 0;
  uint32_t guarded_total = 0;
  mpi_test_world_def(&def);
  def.solver = solver;
  def.integrator = sc->integrator;
  def.features = g_features;
  (void)make_worlds(context, &def, column_min, column_max, stir, &single, &world, &single_tank, &tank);
  if (solver == SPH_SOLVER_DFSPH) {
    sph_dfsph_params dfsph;
    REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK, "dfsph params init");
    if (!divergence_solve) dfsph.flags |= SPH_DFSPH_SKIP_DIVERGENCE_SOLVE;
    dfsph.linear_solver = sc->linear_solver;
    dfsph.max_iterations = sc->max_iterations;
    /* Bounds 100 (density) and 10 (divergence) times tighter than the defaults (the header says
     * why). */
    dfsph.density_error = 1e-5f;
    dfsph.divergence_error = 1e-6f;          /* the share below governs: */
    dfsph.divergence_error_per_step = 1e-4f; /* 0.1/s at 1 ms, through the division each backend does */
    REQUIRE(sph_world_set_dfsph_params(world, &dfsph) == SPH_OK, "dfsph params");
    if (single) REQUIRE(sph_world_set_dfsph_params(single, &dfsph) == SPH_OK, "dfsph params");
  }
  for (int f = 0; f < 2; ++f) {
    sph_stats got, want;
    uint32_t events;
    const char* differs;
    mpi_test_step_stats(world, sc->frames[f], 1, &got);
    if (g_rank == 0) mpi_test_step_stats(single, sc->frames[f], 0, &want);
    events = capped_events(world);
    capped_total += got.pressure_solves_capped;
    guarded_total += got.pressure_solves_guarded;
    differs = mpi_test_solver_stats_differ(&got);
    CHECK(differs == NULL, "%s frame %d: the ranks' stats differ in %s", name, f, differs);
    CHECK(same_on_every_rank(&events, (int)sizeof events), "%s frame %d: the ranks count other capped events",
          name, f);
    CHECK(solver != SPH_SOLVER_DFSPH || got.pressure_iterations > 0, "%s: no density solve iterations", name);
    CHECK(solver != SPH_SOLVER_DFSPH || divergence_solve == 0 || got.divergence_iterations > 0,
          "%s: no divergence solve iterations", name);
    /* The tight bound (the header) is what ends the stirred column's divergence solves, not their
     * minimum of one iteration a substep. */
    CHECK(solver != SPH_SOLVER_DFSPH || divergence_solve == 0 || sc->stir == 0.0f ||
              got.divergence_iterations > sc->frames[f],
          "%s frame %d: %u divergence iterations in %u substeps, the solve's minimum", name, f,
          got.divergence_iterations, sc->frames[f]);
    if (g_rank == 0) {
      CHECK(got.pressure_iterations == want.pressure_iterations &&
                got.divergence_iterations == want.divergence_iterations &&
                got.pressure_iterations_max == want.pressure_iterations_max &&
                got.divergence_iterations_max == want.divergence_iterations_max,
            "%s frame %d: iterations %u/%u (density), %u/%u (divergence); the undivided world %u/%u, %u/%u",
            name, f, got.pressure_iterations, got.pressure_iterations_max, got.divergence_iterations,
            got.divergence_iterations_max, want.pressure_iterations, want.pressure_iterations_max,
            want.divergence_iterations, want.divergence_iterations_max);
      CHECK(memcmp(&got.density_error_mean, &want.density_error_mean, sizeof(float)) == 0 &&
                memcmp(&got.divergence_error_mean, &want.divergence_error_mean, sizeof(float)) == 0 &&
                memcmp(&got.density_error_largest, &want.density_error_largest, sizeof(float)) == 0,
            "%s frame %d: mean errors %g, %g, largest %g; the undivided world %g, %g, %g", name, f,
            (double)got.density_error_mean, (double)got.divergence_error_mean,
            (double)got.density_error_largest, (double)want.density_error_mean,
            (double)want.divergence_error_mean, (double)want.density_error_largest);
      CHECK(got.pressure_solves_capped == want.pressure_solves_capped &&
                got.divergence_solves_capped == want.divergence_solves_capped &&
                events == capped_events(single) && events == got.pressure_solves_capped,
            "%s frame %d: %u/%u capped solves (density/divergence), %u events; the undivided world %u/%u, %u",
            name, f, got.pressure_solves_capped, got.divergence_solves_capped, events,
            want.pressure_solves_capped, want.divergence_solves_capped, capped_events(single));
      CHECK(got.pressure_solves_guarded == want.pressure_solves_guarded,
            "%s frame %d: %u density solves guarded; the undivided world %u", name, f,
            got.pressure_solves_guarded, want.pressure_solves_guarded);
      if (f == 1 && solver == SPH_SOLVER_DFSPH)
        printf(
            "%s: %u density and %u divergence iterations over the last %u substeps, %u capped, %u guarded\n",
            name, got.pressure_iterations, got.divergence_iterations, sc->frames[f],
            got.pressure_solves_capped, got.pressure_solves_guarded);
    }
  }
  CHECK(sc->expect_capped == 2 || (sc->expect_capped ? capped_total > 0 : capped_total == 0),
        "%s: %u capped density solves, expected %s", name, capped_total, sc->expect_capped ? "some" : "none");
  CHECK(sc->expect_guarded ? guarded_total > 0 : guarded_total == 0,
        "%s: %u guarded density solves, expected %s", name, guarded_total,
        sc->expect_guarded ? "some" : "none");
  expect_same_particles(single, world, name);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
}

/* DFSPH's conjugate gradients on a rank of a world whose walls count in the density stay refused
 * (SPH_FEATURE_BOUNDARY_DENSITY, as undivided), naming the feature, the world unchanged. */
static void expect_cg_refused_with_walls(sph_context* context) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_dfsph_params dfsph, now;
  sph_result r;
  mpi_test_world_def(&def);
  def.solver = SPH_SOLVER_DFSPH;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY;
  REQUIRE(sph_mpi_world_create(context, &def, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD), NULL, &world) == SPH_OK,
          "distributed world");
  REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK && sph_dfsph_params_init(&now) == SPH_OK, "dfsph init");
  dfsph.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
  r = sph_world_set_dfsph_params(world, &dfsph);
  CHECK(r == SPH_ERROR_UNSUPPORTED && strstr(sph_get_last_error(), "SPH_FEATURE_BOUNDARY_DENSITY") != NULL,
        "conjugate gradients with the walls' density on a rank: %d '%s'", (int)r, sph_get_last_error());
  REQUIRE(sph_world_get_dfsph_params(world, &now) == SPH_OK, "dfsph params");
  CHECK(now.linear_solver == SPH_DFSPH_JACOBI, "the refused solver was taken");
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
}

int main(int argc, char** argv) {
  const uint32_t jacobi = SPH_DFSPH_JACOBI, cg = SPH_DFSPH_CONJUGATE_GRADIENTS,
                 chebyshev = SPH_DFSPH_CHEBYSHEV;
  const sph_integrator euler = SPH_INTEGRATOR_SYMPLECTIC_EULER, rk4 = SPH_INTEGRATOR_RK4;
  const sph_solver dfsph = SPH_SOLVER_DFSPH, wcsph = SPH_SOLVER_WCSPH;
  /* name, stir, solver, integrator, divergence solve, linear solver, cap, capped, width, frames, guarded */
  const scene scenes[] = {
      {"DFSPH dam break", 0.0f, dfsph, euler, 1, jacobi, 0, 0, 0.1f, {7, 5}, 0},
      {"DFSPH stirred column", 2.0f, dfsph, euler, 1, jacobi, 0, 0, 0.1f, {7, 5}, 0},
      {"DFSPH stirred column, no divergence solve", 2.0f, dfsph, euler, 0, jacobi, 0, 0, 0.1f, {7, 5}, 0},
      {"DFSPH Chebyshev stirred column", 2.0f, dfsph, euler, 1, chebyshev, 0, 0, 0.1f, {7, 5}, 1},
      {"RK4 stirred column", 2.0f, wcsph, rk4, 0, jacobi, 0, 0, 0.1f, {7, 5}, 0},
  };
  const scene cg_scenes[] = {
      {"DFSPH CG dam break", 0.0f, dfsph, euler, 1, cg, 0, 0, 0.2f, {12, 8}, 0},
      {"DFSPH CG stirred column", 2.0f, dfsph, euler, 1, cg, 0, 0, 0.1f, {7, 5}, 0},
      {"DFSPH CG stirred column capped", 2.0f, dfsph, euler, 1, cg, 4, 1, 0.1f, {7, 5}, 0},
  };
  const scene walls[] = {
      {"DFSPH stirred column with walls", 2.0f, dfsph, euler, 1, jacobi, 0, 2, 0.1f, {7, 5}, 0},
      {"RK4 stirred column with walls and loads", 2.0f, wcsph, rk4, 0, jacobi, 0, 2, 0.1f, {7, 5}, 0},
  };
  sph_context* context = NULL;
  mpi_test_init(&argc, &argv, &context);
  if (argc > 1 && strcmp(argv[1], "walls") == 0) {
    /* scripts/validate (45 s a run on 2 cores, for the walls' boundary maps): the walls' share
     * of the density (per particle, before the halo's exchanges) with DFSPH, and with RK4 and the
     * loads' wall reactions. */
    g_features = SPH_FEATURE_BOUNDARY_DENSITY;
    run_scene(context, &walls[0]);
    g_features = SPH_FEATURE_BOUNDARY_DENSITY | SPH_FEATURE_COLLIDER_LOADS;
    run_scene(context, &walls[1]);
    return mpi_test_finish(context, "mpi_solvers");
  }
  if (argc > 1 && strcmp(argv[1], "cg") == 0) {
    /* ctest's mpi_solvers_cg_np1..3 (tests/mpi/CMakeLists.txt). */
    for (size_t i = 0; i < sizeof cg_scenes / sizeof cg_scenes[0]; ++i) run_scene(context, &cg_scenes[i]);
    expect_cg_refused_with_walls(context);
    return mpi_test_finish(context, "mpi_solvers cg");
  }
  for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; ++i) run_scene(context, &scenes[i]);
  return mpi_test_finish(context, "mpi_solvers");
}
