// SPDX-License-Identifier: MIT
/* The solver trade (issue 16 item 5): the dam break of Martin & Moyce (tests/support/dam_break.c)
 * for the weakly compressible scheme at several stiffnesses (Tait's speed of sound as a multiple
 * of the column's free-fall speed sqrt(2 g 2a) = 1.50 m/s) and DFSPH at several density error
 * bounds, at each resolution asked for, on the chosen backend. Per run: wall seconds per
 * simulated second, substeps, neighbour passes, the mean and largest compression (density
 * error) of the particles above rest density ("rho err" in the row; density_error_mean in the CSV,
 * an older name), the mean over every particle of the compression (max(rho/rho0 - 1, 0): the
 * measure DFSPH's bound sets; "over every particle" below the row, mean_density_error_all and
 * above_share in the CSV, and the density solves' own achieved mean, solve_error_mean), the full
 * neighbourhoods' mean |rho/rho0 - 1| and expansion, which the positive part cannot see
 * (interior_error, interior_expansion, interior_share; dam_break.h says which particles count; a host
 * neighbour count each frame, outside the timed steps), the front's mean error against the
 * measurements (one fitted shift, as the validation), and DFSPH's solve iterations, capped solves and the
 * largest error of one particle a density solve ended with ("solve lg", sph_stats.density_error_largest),
 * and an order-free digest of the final positions' bits ("final positions' digest", state_digest in
 * the CSV: two runs agree bit for bit where it agrees; dam_break.h), and the density solves the
 * Chebyshev solve's guard turned to plain steps (sph_stats.pressure_solves_guarded; guarded_substeps in
 * the CSV).
 *
 *   solver_front [--backend cpu|cuda|auto] [--layers 8,12,16] [--seconds 1.0] [--sample-T 0.1]
 *                [--wcsph 5,10,20] [--dfsph 0.01,0.001,0.0001] [--dfsph-solver jacobi|cg|chebyshev]
 *                [--dfsph-max 0.05] [--walls-in-density] [--particle-lanes N] [--no-dfsph-masks]
 *                [--dfsph-lists] [--dfsph-step-factor 0.4] [--dfsph-divergence 1]
 *                [--dfsph-divergence-step 0.001] [--kernel-ratio 1.8] [--slab-layers 6]
 *                [--frame-log] [--out solver_front.csv]
 *
 * --wcsph: the weakly compressible runs' speeds of sound, as multiples of the free-fall speed;
 * --dfsph: the DFSPH runs' density error bounds (0.001 = 0.1 %); `none` leaves a solver out.
 * --dfsph-max: the DFSPH runs' bound on the largest particle error (sph_dfsph_params.density_error_max;
 * default: the library's, 0.05; 1 leaves only the mean bound, as before it existed).
 * --dfsph-solver: the DFSPH solves' linear solver (sph_dfsph_params.linear_solver; default: the
 * library's). --walls-in-density: the tank's walls count in the density and pressure
 * (SPH_FEATURE_BOUNDARY_DENSITY) for both solvers; without it they are collision-only.
 * --particle-lanes: the CUDA context's cuda_particle_lanes (threads per particle of the neighbour
 * passes; 0, the default, is the library's choice). --no-dfsph-masks: the CUDA context's
 * cuda_dfsph_masks = SPH_CUDA_DFSPH_MASKS_OFF (the solves walk every candidate; the same bits).
 * --dfsph-lists: cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS (the solves loop over each
 * particle's neighbour list; the same bits). --dfsph-step-factor: the DFSPH runs' lambda of
 * dt = lambda h / v_max (sph_world_params.step_factor; default the dam break's 0.4; the weakly
 * compressible runs keep 0.4, which their acoustic limit shares). --dfsph-divergence: the DFSPH runs'
 * divergence solve bound as a rate (sph_dfsph_params.divergence_error, 1/s; default the library's, 1);
 * --dfsph-divergence-step: the same bound as a share a step (divergence_error_per_step; default the
 * library's, 0.001). The solve stops at the looser of the two: to measure the rate alone, pass
 * --dfsph-divergence-step 1e-9 (a fixed rate holds the density change a step the tighter the finer
 * the world, docs/validation.md).
 * --kernel-ratio: every run's kernel radius h in particle spacings (sph_world_def.kernel_radius;
 * default the library's, 1.8). The dam break's slab stays 6 layers thick, so a larger h reaches
 * further into its collision-only side walls' deficit; the CUDA solves' masks hold 383 candidates
 * and their lists 63 neighbours (at 2.2 spacings a resting particle has about 64).
 * --slab-layers: the dam break's lattice layers across its thin (z) direction (default 6: two
 * middle layers with a full neighbourhood at 1.8 spacings); more makes it three-dimensional.
 * --frame-log: one line a frame on stdout with the step's statistics and where the densest
 * particle is (in column widths), for diagnosing a run.
 *
 * --sample-T: the front's sampling interval in T (0.1 = 5.4 ms). Each sample ends a frame, and a
 * frame's landing step caps the substep, so a fine sampling (the validation's 0.025 = 1.35 ms)
 * would cap DFSPH's CFL step, which is several times the weakly compressible one, and hide the
 * trade. 0.1 is fine enough for the front: the measurements are 0.2-0.3 apart in T.
 * --seconds: the simulated time (1 s is T = 18.5; the front's comparison window ends at T = 3.3,
 * 0.18 s, so a shorter run, >= 0.2 s, still measures the front). Neighbour passes count the
 * walks over every particle's neighbours: two per substep for the weakly compressible scheme
 * (density, forces), and for DFSPH the density and the forces plus, per solve, the warm start's
 * velocity update and first residual and two per iteration (on CUDA each solve's warm start is
 * gathered in another pass's walk, the density solve's in the force pass, the divergence solve's in
 * the density pass: one pass a solve less). The plot is
 * bench/solver_front_plot.py. A run that fails is a row with status "failed". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dam_break.h"
#include "sph_c.h"
#include "support.h"

#define MAX_RESOLUTIONS 8
#define MAX_RUNS 8
#define GRAVITY 9.81

static int parse_layers(const char* text, uint32_t* layers) {
  int count = 0;
  const char* p = text;
  while (*p && count < MAX_RESOLUTIONS) {
    char* end = NULL;
    const long v = strtol(p, &end, 10);
    if (end == p || v < 4 || v > 1000) return 0;
    layers[count++] = (uint32_t)v;
    p = (*end == ',') ? end + 1 : end;
    if (*end != ',' && *end != '\0') return 0;
  }
  return count;
}

/* A comma-separated list of positive numbers; 0 on a malformed list. */
static int parse_values(const char* text, double* values, int most) {
  int count = 0;
  const char* p = text;
  while (*p && count < most) {
    char* end = NULL;
    const double v = strtod(p, &end);
    if (end == p || !(v > 0.0 && v < 1e6)) return 0;
    values[count++] = v;
    if (*end != ',' && *end != '\0') return 0;
    p = (*end == ',') ? end + 1 : end;
  }
  return *p ? 0 : count;
}

typedef struct solver_run {
  sph_solver solver;
  double value; /* WCSPH: c / free-fall speed; DFSPH: the density error bound */
} solver_run;

int main(int argc, char** argv) {
  double wcsph_values[MAX_RUNS] = {5.0, 10.0, 20.0}, dfsph_values[MAX_RUNS] = {0.01, 0.001, 0.0001};
  int wcsph_count = 3, dfsph_count = 3, run_count = 0;
  solver_run runs[2 * MAX_RUNS];
  uint32_t layers[MAX_RESOLUTIONS] = {8, 12, 16};
  int resolutions = 3;
  double seconds = 1.0, sample_T = 0.1;
  const char* out_path = "solver_front.csv";
  uint32_t linear_solver = 0; /* the library's default */
  uint32_t features = 0, particle_lanes = 0, dfsph_masks = 0;
  double dfsph_max = 0.0;             /* the library's default */
  double dfsph_step_factor = 0.0;     /* 0: the dam break's default */
  double kernel_ratio = 0.0;          /* 0: the library's default (1.8 spacings) */
  uint32_t slab_layers = 0;           /* 0: the dam break's 6 */
  double dfsph_divergence = 0.0;      /* 0: the library's default */
  double dfsph_divergence_step = 0.0; /* 0: the library's default */
  int frame_log = 0;
  sph_backend backend = SPH_BACKEND_AUTO, resolved = SPH_BACKEND_CPU;
  sph_context* context = NULL;
  dam_break_result* result = (dam_break_result*)malloc(sizeof(dam_break_result));
  const double a = DAM_BREAK_COLUMN_WIDTH;
  const double free_fall = sqrt(2.0 * GRAVITY * 2.0 * a);
  const double time_scale = sqrt(2.0 * GRAVITY / a);
  FILE* csv;
  if (!result) return 1;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      backend = support_backend_from_name(argv[++i], SPH_BACKEND_AUTO);
    } else if (strcmp(argv[i], "--layers") == 0 && i + 1 < argc) {
      resolutions = parse_layers(argv[++i], layers);
      if (resolutions == 0) {
        fprintf(stderr, "solver_front: --layers takes a comma-separated list of integers in [4, 1000]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = atof(argv[++i]);
      if (!(seconds >= 0.2 && seconds <= 100.0)) {
        fprintf(stderr, "solver_front: --seconds takes a simulated time in [0.2, 100] s\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--sample-T") == 0 && i + 1 < argc) {
      sample_T = atof(argv[++i]);
      if (!(sample_T >= 0.005 && sample_T <= 0.2)) {
        fprintf(stderr, "solver_front: --sample-T takes an interval in [0.005, 0.2]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--wcsph") == 0 && i + 1 < argc) {
      wcsph_count = strcmp(argv[i + 1], "none") == 0 ? -1 : parse_values(argv[i + 1], wcsph_values, MAX_RUNS);
      ++i;
      if (wcsph_count == 0) {
        fprintf(stderr,
                "solver_front: --wcsph takes up to 8 speeds of sound (multiples of the free-fall speed) or "
                "none\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--dfsph") == 0 && i + 1 < argc) {
      dfsph_count = strcmp(argv[i + 1], "none") == 0 ? -1 : parse_values(argv[i + 1], dfsph_values, MAX_RUNS);
      ++i;
      if (dfsph_count == 0) {
        fprintf(stderr,
                "solver_front: --dfsph takes up to 8 density error bounds (0.001 = 0.1 %%) or none\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      out_path = argv[++i];
    } else if (strcmp(argv[i], "--walls-in-density") == 0) {
      features |= SPH_FEATURE_BOUNDARY_DENSITY;
    } else if (strcmp(argv[i], "--dfsph-max") == 0 && i + 1 < argc) {
      if (parse_values(argv[++i], &dfsph_max, 1) != 1 || dfsph_max > 1.0) {
        fprintf(stderr, "solver_front: --dfsph-max takes one bound in (0, 1]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--particle-lanes") == 0 && i + 1 < argc) {
      particle_lanes = (uint32_t)strtoul(argv[++i], NULL, 10);
    } else if (strcmp(argv[i], "--no-dfsph-masks") == 0) {
      dfsph_masks = SPH_CUDA_DFSPH_MASKS_OFF;
    } else if (strcmp(argv[i], "--slab-layers") == 0 && i + 1 < argc) {
      slab_layers = (uint32_t)strtoul(argv[++i], NULL, 10);
      if (slab_layers < 2 || slab_layers > 4096) {
        fprintf(stderr, "solver_front: --slab-layers takes a layer count in [2, 4096]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--kernel-ratio") == 0 && i + 1 < argc) {
      if (parse_values(argv[++i], &kernel_ratio, 1) != 1 || !(kernel_ratio >= 1.0 && kernel_ratio <= 4.0)) {
        fprintf(stderr, "solver_front: --kernel-ratio takes one h / spacing in [1, 4]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--dfsph-step-factor") == 0 && i + 1 < argc) {
      if (parse_values(argv[++i], &dfsph_step_factor, 1) != 1 || dfsph_step_factor > 10.0) {
        fprintf(stderr, "solver_front: --dfsph-step-factor takes one lambda in (0, 10]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--dfsph-divergence") == 0 && i + 1 < argc) {
      if (parse_values(argv[++i], &dfsph_divergence, 1) != 1 || !(dfsph_divergence > 0.0)) {
        fprintf(stderr, "solver_front: --dfsph-divergence takes one bound > 0 (1/s)\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--dfsph-divergence-step") == 0 && i + 1 < argc) {
      if (parse_values(argv[++i], &dfsph_divergence_step, 1) != 1 || !(dfsph_divergence_step > 0.0) ||
          dfsph_divergence_step > 1.0) {
        fprintf(stderr, "solver_front: --dfsph-divergence-step takes one share in (0, 1]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--dfsph-lists") == 0) {
      dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS;
    } else if (strcmp(argv[i], "--frame-log") == 0) {
      frame_log = 1;
    } else if (strcmp(argv[i], "--dfsph-solver") == 0 && i + 1 < argc) {
      ++i;
      if (strcmp(argv[i], "jacobi") == 0) {
        linear_solver = SPH_DFSPH_JACOBI;
      } else if (strcmp(argv[i], "cg") == 0) {
        linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
      } else if (strcmp(argv[i], "chebyshev") == 0) {
        linear_solver = SPH_DFSPH_CHEBYSHEV;
      } else {
        fprintf(stderr, "solver_front: --dfsph-solver takes jacobi, cg or chebyshev\n");
        return 2;
      }
    } else {
      fprintf(
          stderr,
          "usage: solver_front [--backend cpu|cuda|auto] [--layers 8,12,16] [--seconds 1.0] [--sample-T 0.1] "
          "[--wcsph 5,10,20] [--dfsph 0.01,0.001,0.0001] [--dfsph-solver jacobi|cg|chebyshev] [--dfsph-max "
          "0.05] "
          "[--walls-in-density] [--particle-lanes N] [--no-dfsph-masks] [--dfsph-lists] [--dfsph-step-factor "
          "L] [--dfsph-divergence 1] [--dfsph-divergence-step 0.001] [--kernel-ratio 1.8] [--slab-layers 6] "
          "[--frame-log] "
          "[--out "
          "solver_front.csv]\n");
      return 2;
    }
  }
  for (int k = 0; k < wcsph_count; ++k) runs[run_count++] = (solver_run){SPH_SOLVER_WCSPH, wcsph_values[k]};
  for (int k = 0; k < dfsph_count; ++k) runs[run_count++] = (solver_run){SPH_SOLVER_DFSPH, dfsph_values[k]};
  {
    sph_context_def cdef;
    sph_context_def_init(&cdef);
    cdef.backend = backend;
    cdef.cuda_particle_lanes = particle_lanes;
    cdef.cuda_dfsph_masks = dfsph_masks;
    if (sph_context_create(&cdef, &context) != SPH_OK) context = NULL;
  }
  if (!context) {
    fprintf(stderr, "solver_front: no context for the backend asked for\n");
    return 1;
  }
  sph_context_get_backend(context, &resolved);
  csv = fopen(out_path, "w");
  if (!csv) {
    fprintf(stderr, "solver_front: cannot write %s\n", out_path);
    return 1;
  }
  fprintf(
      csv,
      "backend,solver,parameter,layers,particles,simulated_s,wall_s,wall_s_per_simulated_s,substeps,"
      "neighbor_passes,pressure_iterations,divergence_iterations,density_error_mean,density_error_max,"
      "solve_error_max,front_shift_T,front_error_mean,front_error_max,status,ms_per_substep,neighbors_mean,"
      "ms_hash_sort,ms_cell_ranges,ms_density,ms_forces,ms_integrate,ms_collide,ms_emit,ms_other,"
      "solve_error_largest,mean_density_error_all,above_share,solve_error_mean,interior_error,"
      "interior_expansion,interior_share,state_digest,guarded_substeps\n");
  printf(
      "%s backend; dam break of Martin & Moyce for %.2f simulated s; front errors over T in [%.1f, %.1f]\n",
      resolved == SPH_BACKEND_CUDA ? "CUDA" : "CPU", seconds, DAM_BREAK_T_FIRST, DAM_BREAK_T_LAST);
  printf("%-6s %-9s %6s %9s %10s %9s %10s %8s %8s %8s %8s %8s %6s %9s %6s %8s\n", "solver", "parameter",
         "layers", "particles", "wall/sim", "substeps", "nb passes", "rho err", "rho max", "front", "it/step",
         "div it", "capped", "ms/subst", "nbrs", "solve lg");
  for (int l = 0; l < resolutions; ++l) {
    for (int r = 0; r < run_count; ++r) {
      dam_break_config config;
      sph_result status;
      double passes = 0.0, substep_ms = 0.0;
      const int dfsph = runs[r].solver == SPH_SOLVER_DFSPH;
      dam_break_config_default(&config, layers[l]);
      config.end_T = seconds * time_scale;
      config.sample_T = sample_T;
      config.solver = runs[r].solver;
      config.dfsph_linear_solver = linear_solver;
      config.features |= features;
      config.frame_log = frame_log ? stdout : NULL;
      config.measure_interior = 1;
      config.kernel_ratio = (float)kernel_ratio;
      if (slab_layers) config.slab_layers = slab_layers;
      if (dfsph) {
        config.density_error = (float)runs[r].value;
        config.density_error_max = (float)dfsph_max;
        if (dfsph_step_factor > 0.0) config.step_factor = (float)dfsph_step_factor;
        if (dfsph_divergence > 0.0) config.divergence_error = (float)dfsph_divergence;
        if (dfsph_divergence_step > 0.0) config.divergence_error_per_step = (float)dfsph_divergence_step;
      } else {
        config.speed_of_sound = (float)(runs[r].value * free_fall);
      }
      status = dam_break_run(context, &config, result, NULL, NULL);
      if (status != SPH_OK) {
        fprintf(csv, "%s,%s,%g,%u,%u,,,,,,,,,,,,,,failed\n", resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu",
                dfsph ? "dfsph" : "wcsph", runs[r].value, layers[l], result->particles);
        printf("%-6s %-9g %6u failed: %s\n", dfsph ? "DFSPH" : "WCSPH", runs[r].value, layers[l],
               result->message);
        continue;
      }
      passes = 2.0 * (double)result->substeps;
      substep_ms = result->substeps ? 1e3 * result->wall_seconds / (double)result->substeps : 0.0;
      if (dfsph) {
        /* Per solve: the warm start's update and the first residual, then two per iteration. */
        const double solves = (double)result->substeps * (config.dfsph_flags ? 1.0 : 2.0);
        passes += 2.0 * solves + 2.0 * (double)(result->pressure_iterations + result->divergence_iterations);
        /* On CUDA each solve's warm start rides in another pass's walk: the density solve's in the
         * force pass (session 36), the divergence solve's in the density pass (session 37). */
        if (resolved == SPH_BACKEND_CUDA) passes -= solves;
      }
      fprintf(
          csv, "%s,%s,%g,%u,%u,%.4f,%.3f,%.3f,%llu,%.0f,%llu,%llu,%.6f,%.6f,%.6f,%.4f,%.5f,%.5f,ok,%.5f,%.2f",
          resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu", dfsph ? "dfsph" : "wcsph", runs[r].value, layers[l],
          result->particles, result->simulated_seconds, result->wall_seconds,
          result->wall_seconds / result->simulated_seconds, (unsigned long long)result->substeps, passes,
          (unsigned long long)result->pressure_iterations, (unsigned long long)result->divergence_iterations,
          result->mean_compression, result->max_compression, result->density_error_max, result->shift_T,
          result->mean_error, result->max_error, substep_ms, result->neighbors_mean);
      for (int k = 0; k < SPH_STAGE_COUNT; ++k)
        fprintf(csv, ",%.5f", result->substeps ? result->stage_ms[k] / (double)result->substeps : 0.0);
      fprintf(csv, ",%.6f,%.6f,%.4f,%.6f,%.6f,%.6f,%.4f,%016llx,%u\n", result->density_error_largest,
              result->mean_density_error, result->above_share, result->density_error_mean,
              result->interior_error, result->interior_expansion, result->interior_share,
              (unsigned long long)result->state_digest, result->guarded_substeps);
      fflush(csv);
      printf(
          "%-6s %-9g %6u %9u %10.2f %9llu %10.0f %7.2f%% %7.2f%% %7.2f%% %8.2f %8.2f %6u %9.4f %6.1f "
          "%7.2f%%\n",
          dfsph ? "DFSPH" : "WCSPH", runs[r].value, layers[l], result->particles,
          result->wall_seconds / result->simulated_seconds, (unsigned long long)result->substeps, passes,
          100.0 * result->mean_compression, 100.0 * result->max_compression, 100.0 * result->mean_error,
          dfsph ? (double)result->pressure_iterations / (double)result->substeps : 0.0,
          dfsph ? (double)result->divergence_iterations / (double)result->substeps : 0.0,
          result->capped_substeps, substep_ms, result->neighbors_mean, 100.0 * result->density_error_largest);
      printf(
          "       over every particle: mean density error %.4f%% (%.1f%% of them above rest); the density "
          "solves' mean error %.4f%%; %u of them guarded (the Chebyshev solve's plain steps)\n",
          100.0 * result->mean_density_error, 100.0 * result->above_share, 100.0 * result->density_error_mean,
          result->guarded_substeps);
      printf(
          "       full neighbourhoods (%.1f%% of the particles): mean |rho/rho0 - 1| %.4f%%, expansion "
          "%.4f%%\n",
          100.0 * result->interior_share, 100.0 * result->interior_error, 100.0 * result->interior_expansion);
      printf("       stages, ms/substep:");
      for (int k = 0; k < SPH_STAGE_COUNT; ++k)
        printf(" %.4f", result->substeps ? result->stage_ms[k] / (double)result->substeps : 0.0);
      printf(" (hash+sort, cell ranges, density, forces, integrate, collide, emit, other)\n");
      printf("       final positions' digest %016llx\n", (unsigned long long)result->state_digest);
      fflush(stdout);
    }
  }
  fclose(csv);
  free(result);
  sph_context_destroy(context);
  return 0;
}
