// SPDX-License-Identifier: MIT
/* The dam-break case of Martin & Moyce (1952), shared by the validation test
 * (tests/validation/test_dam_break.c) and the speed-accuracy benchmark (bench/speed_accuracy.c).
 * Plain C on the public API only, no test framework, so a benchmark can link it (part of
 * tests/support; its lattice and tank are support.h's).
 *
 * A column of water, width a and height 2a, stands against the back wall of a long tank and is
 * released at t = 0. The surge front z(t) along the floor is compared with the measurements in
 * dimensionless form, Z = z / a against T = t sqrt(2 g / a) (n^2 = 2 in their notation). The
 * setup and every choice in it are explained in docs/validation.md and in dam_break.c. */
#ifndef SPH_VALIDATION_DAM_BREAK_H
#define SPH_VALIDATION_DAM_BREAK_H

#include <stdint.h>

#include <stdio.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Martin & Moyce's column width, 2.25 in (their Table 2 for n^2 = 2). */
#define DAM_BREAK_COLUMN_WIDTH 0.05715f
/* The measured points: T and Z, from ../shared/data/martin_moyce_1952_front_n2.csv. */
#define DAM_BREAK_MEASUREMENTS 16
extern const double dam_break_measured_T[DAM_BREAK_MEASUREMENTS];
extern const double dam_break_measured_Z[DAM_BREAK_MEASUREMENTS];
/* The comparison window and its one allowed time shift. */
#define DAM_BREAK_T_FIRST 0.8
#define DAM_BREAK_T_LAST 3.3
#define DAM_BREAK_MAX_SHIFT 0.2

typedef struct dam_break_config {
  uint32_t layers_across;    /* lattice layers across the column width a (the resolution) */
  uint32_t slab_layers;      /* lattice layers across the slab (the thin z direction) */
  sph_integrator integrator; /* symplectic Euler or RK4 */
  float step_factor;         /* lambda of the step controller (and of the acoustic limit) */
  float speed_of_sound;      /* Tait's c, m/s */
  float viscosity;           /* Mueller's mu, Pa s */
  float friction;            /* Coulomb coefficient of the tank walls (0: free slip) */
  double end_T;              /* simulate until this T */
  double sample_T;           /* sample the front every sample_T */
  /* The solver (0: SPH_SOLVER_WCSPH, the validation's). With SPH_SOLVER_DFSPH the world has no
   * equation of state (speed_of_sound and the acoustic limit are not used) and these are its
   * sph_dfsph_params (0: the library's default): */
  sph_solver solver;
  float density_error;
  float density_error_max; /* the bound on the largest particle error (0: the library's default) */
  float divergence_error;
  float divergence_error_per_step; /* the divergence bound's share a step (0: the library's default) */
  uint32_t max_iterations;
  uint32_t dfsph_flags;
  uint32_t dfsph_linear_solver; /* SPH_DFSPH_JACOBI, _CONJUGATE_GRADIENTS or _CHEBYSHEV (0: default) */
  uint32_t features;  /* sph_world_def.features added to the world's (e.g. SPH_FEATURE_BOUNDARY_DENSITY) */
  float kernel_ratio; /* h in particle spacings (0: the library's default, 1.8) */
  FILE* frame_log;    /* optional (NULL: none): one line a frame of the step's statistics and where the
                         densest particle is, for diagnosing a run */
  /* Nonzero: measure the full neighbourhoods' density error each frame (interior_* below; a host
     neighbour count over every particle, seconds a frame at a million particles, outside the
     timed steps). 0 (the default): those fields stay 0. */
  int measure_interior;
  /* Nonzero: after the first frame whose density solves the Chebyshev guard turned, save the world
     to memory, load it into a second world and compare the two worlds' solver statistics
     (reload_* below). 0 (the default): no save. */
  int check_reload;
} dam_break_config;

/* The share of the start's fullest neighbour count (within h, itself included) from which a
   particle counts as having a full neighbourhood. On the start's FCC lattice (h = 2.55 lattice
   steps) a particle of the slab's middle layers has 43 neighbours and one of the layers 1.5 steps
   from a collision-only wall 38 (88 %), so both count; a particle within about h / 2 of a free
   surface has fewer than 85 %. An expanded particle leaves the set as it loses neighbours (the
   second layers after about 5 %), so interior_share falls where the water spreads. */
#define DAM_BREAK_FULL_NEIGHBORHOOD_SHARE 0.85

/* The configuration the validation uses (docs/validation.md says why each value). */
void dam_break_config_default(dam_break_config* config, uint32_t layers_across);

#define DAM_BREAK_MAX_SAMPLES 1024

typedef struct dam_break_result {
  uint32_t particles;
  uint32_t samples;
  double T[DAM_BREAK_MAX_SAMPLES]; /* sample times (dimensionless) */
  double Z[DAM_BREAK_MAX_SAMPLES]; /* the surge front at those times (dimensionless) */
  double spacing;                  /* particle spacing, m */
  double simulated_seconds;
  double wall_seconds; /* inside sph_world_step only */
  uint64_t substeps;
  double mean_compression; /* mean over samples of the mean (rho/rho0 - 1) of the
                              particles above rest density */
  double max_compression;  /* the largest density_max / rho0 - 1 seen */
  /* mean over samples of the mean over every particle of max(rho/rho0 - 1, 0): the measure of
     DFSPH's bound (sph_dfsph_params.density_error, Bender & Koschier's average density error); a
     sample's mean_compression is this divided by the share above rest */
  double mean_density_error;
  double above_share; /* mean over samples of the share of particles above rest density */
  /* With config.measure_interior, the particles with a full neighbourhood
     (DAM_BREAK_FULL_NEIGHBORHOOD_SHARE), mean over the samples that had any: their mean
     |rho/rho0 - 1| (expansion counts, which mean_density_error leaves out), their mean expansion
     max(1 - rho/rho0, 0); and their share of the particles, mean over samples. */
  double interior_error;
  double interior_expansion;
  double interior_share;
  /* The comparison with the measurements over T in [T_FIRST, T_LAST]: */
  double shift_T;              /* the fitted shift: simulation at T + shift against data at T */
  double mean_error;           /* mean |Z_sim - Z_meas| / Z_meas at the fitted shift */
  double max_error;            /* worst point at the fitted shift */
  double mean_error_unshifted; /* the same without a shift */
  double max_error_unshifted;
  uint32_t compared; /* measured points in the window */
  uint32_t escaped;  /* particles outside the tank at the end */
  /* DFSPH's solves over the run (sph_stats), zero for WCSPH: */
  uint64_t pressure_iterations;   /* density-solve iterations, summed over the substeps */
  uint64_t divergence_iterations; /* divergence-solve iterations, summed */
  uint32_t pressure_iterations_max;
  double density_error_mean;    /* the density solve's achieved mean error, averaged over substeps */
  double density_error_max;     /* the largest of any substep */
  double density_error_largest; /* the largest error of one particle any density solve ended with
                                   (sph_stats.density_error_largest; within density_error_max unless
                                   that solve was capped) */
  uint32_t capped_substeps;     /* substeps whose density solve stopped at its cap (sph_stats) */
  uint32_t guarded_substeps;    /* substeps whose Chebyshev density solve its guard turned to plain
                                   steps (sph_stats.pressure_solves_guarded) */
  uint32_t capped_events;       /* the counts of SPH_EVENT_PRESSURE_SOLVE_CAPPED events, summed */
  /* With config.check_reload: whether the reload happened (a frame had a guarded solve), and
     whether the loaded world's statistics had the saved world's solver fields, bit for bit
     (pressure_iterations ... density_error_largest, and pressure_solves_guarded). */
  int reload_checked;
  int reload_stats_equal;
  /* Where the wall time went (sph_stats' stage_ms summed over the frames, ms) and the mean
   * neighbour count (sph_stats' neighbors_mean, weighted by the frames' substeps): what tells
   * two runs' substep costs apart (bench/solver_front prints them). */
  double stage_ms[SPH_STAGE_COUNT];
  double neighbors_mean;
  /* An order-free digest of the last frame's positions, bit for bit (position_digest in
     dam_break.c): equal for two runs whose final positions are the same bits, whatever their
     storage order; different (but for a 2^-64 chance) if any bit of any position differs. What
     tells two builds or two neighbour walks apart at a million particles, where the printed
     statistics may agree while the bits do not. Zero if the run stopped before its last frame. */
  uint64_t state_digest;
  char message[256]; /* the failing call's message when the run failed */
} dam_break_result;

/* Runs the case on `context`. Returns SPH_OK or the first failing call's result (its message
 * in result->message). trace (optional) receives one line per sample: T, Z. */
sph_result dam_break_run(sph_context* context, const dam_break_config* config, dam_break_result* result,
                         void (*trace)(void* user, double T, double Z), void* trace_user);

/* Compares a front history with the measurements at a given shift (no fitting). */
void dam_break_compare(const dam_break_result* result, double shift_T, double* mean_error, double* max_error,
                       uint32_t* compared);

#ifdef __cplusplus
}
#endif

#endif
