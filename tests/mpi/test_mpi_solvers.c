/* SPDX-License-Identifier: MIT */
/* The DFSPH solver and the RK4 integrator in a distributed world (docs/distributed.md) against one
 * undivided world, under mpirun on 1-4 ranks. RK4 sorts four times a substep: each stage gathers
 * its halo, and the stage's state (rk4_start, rk4_sum) moves with a particle that changes ranks
 * between stages. DFSPH: each solve iteration's neighbour passes read the ghosts' velocities
 * and pressure steps, which cross the halo after each pass, and its convergence test reads the
 * world's mean error, an exact sum over the ranks. Scenes: the dam break and the stirred
 * column (particles crossing the slab boundaries every few substeps), with the divergence solve
 * (the default) and without it, and RK4's stirred column, 12 substeps each (frames of 7 and 5).
 * Checked:
 *   - the gathered particles equal the undivided world's bit for bit: every sum of a pass runs in
 *     the undivided world's order (the halo's sort keys), and the mean error is an exact sum
 *     (exact_float_sum.h) whose bins the ranks add (a solve that stopped one iteration apart
 *     would move every particle);
 *   - the solves' iteration counts and achieved mean errors (sph_stats) are the undivided world's,
 *     and the same on every rank.
 * The bounds are 100 (density) and 10 (divergence) times tighter than the defaults, so the convergence test
 * rather than the minimum ends the stirred column's solves (19 density and 12 divergence iterations over the
 * last 5 substeps). Without the velocities' or the pressure steps' exchange, 1278-1404 of the 1404 particles
 * differ on 2 ranks. */
#include "mpi_compare.h"

static uint32_t g_features = SPH_FEATURE_NONE; /* the def's features ("walls": the walls' density) */

static void run_scene(sph_context* context, const char* name, float stir, sph_solver solver,
                      sph_integrator integrator, uint32_t divergence_solve) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank, tank;
  const uint32_t frames[2] = {7, 5};
  mpi_test_world_def(&def);
  def.solver = solver;
  def.integrator = integrator;
  def.features = g_features;
  (void)make_worlds(context, &def, column_min, column_max, stir, &single, &world, &single_tank, &tank);
  if (solver == SPH_SOLVER_DFSPH) {
    sph_dfsph_params dfsph;
    REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK, "dfsph params init");
    if (!divergence_solve) dfsph.flags |= SPH_DFSPH_SKIP_DIVERGENCE_SOLVE;
    /* Bounds 100 (density) and 10 (divergence) times tighter than the defaults (the header says
     * why). */
    dfsph.density_error = 1e-5f;
    dfsph.divergence_error = 0.1f;
    REQUIRE(sph_world_set_dfsph_params(world, &dfsph) == SPH_OK, "dfsph params");
    if (single) REQUIRE(sph_world_set_dfsph_params(single, &dfsph) == SPH_OK, "dfsph params");
  }
  for (int f = 0; f < 2; ++f) {
    sph_stats got, want;
    uint32_t solves[4];
    float errors[2];
    mpi_test_step_stats(world, frames[f], 1, &got);
    if (g_rank == 0) mpi_test_step_stats(single, frames[f], 0, &want);
    solves[0] = got.pressure_iterations;
    solves[1] = got.pressure_iterations_max;
    solves[2] = got.divergence_iterations;
    solves[3] = got.divergence_iterations_max;
    errors[0] = got.density_error_mean;
    errors[1] = got.divergence_error_mean;
    CHECK(same_on_every_rank(solves, (int)sizeof solves) && same_on_every_rank(errors, (int)sizeof errors),
          "%s: the ranks ran different iterations", name);
    CHECK(solver != SPH_SOLVER_DFSPH || got.pressure_iterations > 0, "%s: no density solve iterations", name);
    CHECK(solver != SPH_SOLVER_DFSPH || divergence_solve == 0 || got.divergence_iterations > 0,
          "%s: no divergence solve iterations", name);
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
                memcmp(&got.divergence_error_mean, &want.divergence_error_mean, sizeof(float)) == 0,
            "%s frame %d: mean errors %g, %g; the undivided world %g, %g", name, f,
            (double)got.density_error_mean, (double)got.divergence_error_mean,
            (double)want.density_error_mean, (double)want.divergence_error_mean);
      if (f == 1 && solver == SPH_SOLVER_DFSPH)
        printf("%s: %u density and %u divergence iterations over the last %u substeps\n", name,
               got.pressure_iterations, got.divergence_iterations, frames[f]);
    }
  }
  expect_same_particles(single, world, name);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
}

int main(int argc, char** argv) {
  sph_context* context = NULL;
  mpi_test_init(&argc, &argv, &context);
  if (argc > 1 && strcmp(argv[1], "walls") == 0) {
    /* scripts/validate (45 s a run on 2 cores, for the walls' boundary maps): the walls' share
     * of the density (per particle, before the halo's exchanges) with DFSPH, and with RK4 and the
     * loads' wall reactions. */
    g_features = SPH_FEATURE_BOUNDARY_DENSITY;
    run_scene(context, "DFSPH stirred column with walls", 2.0f, SPH_SOLVER_DFSPH,
              SPH_INTEGRATOR_SYMPLECTIC_EULER, 1);
    g_features = SPH_FEATURE_BOUNDARY_DENSITY | SPH_FEATURE_COLLIDER_LOADS;
    run_scene(context, "RK4 stirred column with walls and loads", 2.0f, SPH_SOLVER_WCSPH, SPH_INTEGRATOR_RK4,
              0);
    return mpi_test_finish(context, "mpi_solvers");
  }
  run_scene(context, "DFSPH dam break", 0.0f, SPH_SOLVER_DFSPH, SPH_INTEGRATOR_SYMPLECTIC_EULER, 1);
  run_scene(context, "DFSPH stirred column", 2.0f, SPH_SOLVER_DFSPH, SPH_INTEGRATOR_SYMPLECTIC_EULER, 1);
  run_scene(context, "DFSPH stirred column without the divergence solve", 2.0f, SPH_SOLVER_DFSPH,
            SPH_INTEGRATOR_SYMPLECTIC_EULER, 0);
  run_scene(context, "RK4 stirred column", 2.0f, SPH_SOLVER_WCSPH, SPH_INTEGRATOR_RK4, 0);
  return mpi_test_finish(context, "mpi_solvers");
}
