// SPDX-License-Identifier: MIT
/*
 * rest_sphere - BENCHMARK.md case 1, the thesis benchmark: particles on an FCC lattice in a
 * sphere at rest density, no gravity, no colliders, dt_max = 1 ms (40 substeps in a 25 fps
 * frame at rest), library defaults otherwise. Case "rest" starts at zero velocity, case
 * "moving" with every velocity component uniform in [-0.1, 0.1] m/s. Uses only the public C
 * API (sph_c.h); the sphere and its velocities come from tests/support (support_fcc_sphere,
 * support_random_velocities).
 *
 *   rest_sphere [--particles N|largest] [--frames F] [--warmup W] [--backend cpu|cuda|auto]
 *               [--case rest|moving|both] [--option NAME] [--json FILE] [--csv FILE] [--label TEXT]
 *               [--cuda-frames graph|stream] [--density-block N] [--force-block N]
 *               [--particle-lanes N] [--threads N] [--dfsph-masks on|off|lists]
 *
 * --threads sets the CPU backend's workers (sph_context_def.cpu_worker_count), so that a run on a
 * larger host can measure two workers (issue 18's CPU goal); pin them with taskset to two cores.
 *
 * --option turns one optional piece of physics on, to measure what it costs (BENCHMARK.md,
 * issue 5): none (default), surface_tension, normalized_density, density_diffusion (with the
 * normalised density it needs: compare with normalized_density), clavet (viscosity), tait
 * (equation of state), rk4 (integrator), acoustic_limit (step limit), springs (elasticity with
 * the default sph_spring_params, whose step ceiling, 1.25 ms, is above dt_max: the same
 * substeps, so the cost is the spring work; the springs are made in the first warm-up
 * substep), dfsph (the incompressible solver, SPH_SOLVER_DFSPH, with its default bounds: at rest
 * its cost is the factor pass and the solves' minimum iterations, all neighbour passes).
 * --particles largest
 * finds the largest world the device holds (world creation refused with OUT_OF_*_MEMORY
 * above it) and runs 95 % of that.
 *
 * --cuda-frames, --density-block and --force-block set the CUDA tuning of sph_context_def
 * (cuda_frames, cuda_density_block, cuda_force_block; docs/cuda.md): the stream driver launches
 * kernel by kernel, which is what a profiler such as ncu needs (scripts/bench-gpu).
 * --particle-lanes sets cuda_particle_lanes (threads per particle of the neighbour passes: 1, 2,
 * 4 or 8; scripts/bench-lanes compares them). --dfsph-masks off sets cuda_dfsph_masks =
 * SPH_CUDA_DFSPH_MASKS_OFF (with --option dfsph: the world's bytes without the candidate masks);
 * --dfsph-masks lists sets SPH_CUDA_DFSPH_NEIGHBOR_LISTS (the solves loop over neighbour lists).
 *
 * Prints a table per case; --json writes the results as a JSON array, --csv appends rows
 * (with a header when the file is new). Times are the wall time of sph_world_step (which
 * blocks until the frame is done), median over the timed frames after the warm-up; the stage
 * breakdown is the library's own per-stage timing (sph_stats.stage_ms).
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sph_c.h"
#include "support.h"

#define FRAME_DT 0.04f /* 25 frames per second */

typedef struct options {
  uint32_t particles;
  int largest; /* --particles largest */
  const char* option;
  int frames;
  int warmup;
  sph_backend backend;
  const char* which; /* rest | moving | both */
  const char* json;
  const char* csv;
  const char* label;
  sph_cuda_frames cuda_frames;
  uint32_t density_block; /* 0: the library's default */
  uint32_t force_block;
  uint32_t particle_lanes; /* 0: the library's choice */
  uint32_t threads;        /* CPU workers; 0: the library's default, one per processor */
  uint32_t
      dfsph_masks; /* sph_context_def.cuda_dfsph_masks: 0 on, SPH_CUDA_DFSPH_MASKS_OFF, _NEIGHBOR_LISTS */
} options;

typedef struct result {
  const char* scene;
  const char* option;
  const char* backend;
  uint32_t count;
  uint32_t substeps_per_frame;
  double ms_per_frame;   /* median */
  double ms_per_substep; /* median of step_ms / substeps */
  double particle_substeps_per_s;
  double neighbors_mean;
  uint32_t neighbors_max;
  double bytes_per_particle;
  double stage_ms_per_substep[SPH_STAGE_COUNT]; /* mean over the timed frames */
  double density_error_mean;                    /* (mean density - rho0) / rho0 at the end */
  double pressure_iterations;                   /* DFSPH: density solve iterations per substep */
  double divergence_iterations;                 /* DFSPH: divergence solve iterations per substep */
  double density_min, density_max;
  double max_speed;
  double setup_s;
} result;

static void check(sph_result r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "rest_sphere: %s failed: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
    exit(1);
  }
}

static int compare_double(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

static double median(double* v, int n) {
  qsort(v, (size_t)n, sizeof *v, compare_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The world definition and parameters of the case, with --option applied. */
static void describe_world(const options* o, uint32_t capacity, sph_world_def* def,
                           sph_world_params* params) {
  sph_world_def_init(def);
  def->capacity = capacity;
  def->particle_spacing = 0.02f;
  sph_world_params_init(params);
  params->gravity.x = params->gravity.y = params->gravity.z = 0.0f;
  params->dt_max = 1e-3f;
  if (strcmp(o->option, "surface_tension") == 0) {
    def->features |= SPH_FEATURE_SURFACE_TENSION;
  } else if (strcmp(o->option, "normalized_density") == 0) {
    def->features |= SPH_FEATURE_NORMALIZED_DENSITY;
  } else if (strcmp(o->option, "density_diffusion") == 0) {
    /* The diffusion needs the normalised density: compare with --option normalized_density. */
    def->features |= SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION;
  } else if (strcmp(o->option, "clavet") == 0) {
    def->viscosity_method = SPH_VISCOSITY_CLAVET;
  } else if (strcmp(o->option, "tait") == 0) {
    def->equation_of_state = SPH_EOS_TAIT;
  } else if (strcmp(o->option, "rk4") == 0) {
    def->integrator = SPH_INTEGRATOR_RK4;
  } else if (strcmp(o->option, "acoustic_limit") == 0) {
    params->step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  } else if (strcmp(o->option, "springs") == 0) {
    def->features |= SPH_FEATURE_SPRINGS;
  } else if (strcmp(o->option, "dfsph") == 0) {
    def->solver = SPH_SOLVER_DFSPH;
  } else if (strcmp(o->option, "none") != 0) {
    fprintf(stderr, "rest_sphere: unknown --option '%s'\n", o->option);
    exit(2);
  }
}

/* The largest capacity a world can be created with on this backend: halves down from the
 * API's limit (2^30 particles) until a world fits, then bisects (to 1 %) between the largest
 * that fit and the smallest that did not. Only out-of-memory refusals count as "does not
 * fit". */
#define CAPACITY_LIMIT 1073741824.0 /* sph_world_def.capacity <= 2^30 */
static uint32_t largest_capacity(const options* o, sph_context* context) {
  double fits = 0.0, too_big = 2.0 * CAPACITY_LIMIT;
  while (too_big - fits > 0.01 * too_big) {
    const double trial = floor(fits > 0.0 ? 0.5 * (fits + too_big) : 0.5 * too_big);
    sph_world_def def;
    sph_world_params params;
    describe_world(o, (uint32_t)trial, &def, &params);
    sph_world* world = NULL;
    const sph_result r = sph_world_create(context, &def, &world);
    if (r == SPH_OK) {
      sph_world_destroy(world);
      fits = trial;
      if (fits >= CAPACITY_LIMIT) break; /* the API's limit fits */
    } else if (r == SPH_ERROR_OUT_OF_DEVICE_MEMORY || r == SPH_ERROR_OUT_OF_HOST_MEMORY) {
      too_big = trial;
    } else {
      check(r, "sph_world_create (probing the largest world)");
    }
  }
  printf("largest world that can be created: %.0f particles (refused at %.0f)\n", fits, too_big);
  return (uint32_t)fits;
}

static result run_case(const options* o, int moving) {
  result r;
  memset(&r, 0, sizeof r);
  r.scene = moving ? "moving" : "rest";
  r.option = o->option;
  const double t0 = now_s();
  const float spacing = 0.02f;

  sph_context_def cdef;
  sph_context_def_init(&cdef);
  cdef.backend = o->backend;
  cdef.cuda_frames = o->cuda_frames;
  cdef.cuda_density_block = o->density_block;
  cdef.cuda_force_block = o->force_block;
  cdef.cuda_particle_lanes = o->particle_lanes;
  cdef.cpu_worker_count = o->threads;
  cdef.cuda_dfsph_masks = o->dfsph_masks;
  sph_context* context = NULL;
  check(sph_context_create(&cdef, &context), "sph_context_create");
  sph_backend resolved;
  check(sph_context_get_backend(context, &resolved), "sph_context_get_backend");
  r.backend = resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu";

  /* The largest run: 95 % of the largest world, leaving room for what a step allocates. */
  const double wanted = o->largest ? 0.95 * largest_capacity(o, context) : (double)o->particles;
  double radius = spacing * cbrt(3.0 * wanted / (4.0 * 3.14159265358979 * sqrt(2.0)));
  uint32_t count = 0;
  float* positions = NULL;
  sph_result lattice = support_fcc_sphere(NULL, radius, spacing, &positions, &count);
  while (lattice == SPH_OK && o->largest && count > wanted) { /* the volume estimate can overshoot */
    free(positions);
    radius *= 0.999;
    lattice = support_fcc_sphere(NULL, radius, spacing, &positions, &count);
  }
  float* velocities = calloc((size_t)count * 3 + 3, sizeof(float));
  if (lattice != SPH_OK || !velocities) {
    fprintf(stderr, "rest_sphere: out of host memory\n");
    exit(1);
  }
  if (moving) {
    uint64_t seed = 0x5eed5eed12345ull;
    support_random_velocities(velocities, count, 0.1, NULL, &seed);
  }

  sph_world_def def;
  sph_world_params params;
  describe_world(o, count, &def, &params);
  sph_world* world = NULL;
  check(sph_world_create(context, &def, &world), "sph_world_create");
  check(sph_world_set_params(world, &params), "sph_world_set_params");
  check(support_spawn(world, positions, velocities, count), "sph_world_spawn");
  free(positions);
  free(velocities);
  r.count = count;
  r.setup_s = now_s() - t0;

  for (int f = 0; f < o->warmup; ++f) check(sph_world_step(world, FRAME_DT), "sph_world_step (warm-up)");
  double* frame_ms = malloc(sizeof(double) * (size_t)o->frames);
  double* substep_ms = malloc(sizeof(double) * (size_t)o->frames);
  double stage_sum[SPH_STAGE_COUNT] = {0};
  uint64_t substeps_total = 0, pressure_iterations = 0, divergence_iterations = 0;
  sph_stats s;
  sph_stats_init(&s);
  for (int f = 0; f < o->frames; ++f) {
    check(sph_world_step(world, FRAME_DT), "sph_world_step");
    check(sph_world_get_stats(world, &s), "sph_world_get_stats");
    frame_ms[f] = s.step_ms;
    substep_ms[f] = s.substeps ? s.step_ms / s.substeps : 0.0;
    substeps_total += s.substeps;
    pressure_iterations += s.pressure_iterations;
    divergence_iterations += s.divergence_iterations;
    for (int k = 0; k < SPH_STAGE_COUNT; ++k) stage_sum[k] += s.stage_ms[k];
  }
  r.substeps_per_frame = s.substeps;
  r.ms_per_frame = median(frame_ms, o->frames);
  r.ms_per_substep = median(substep_ms, o->frames);
  r.particle_substeps_per_s = r.ms_per_substep > 0 ? count / (r.ms_per_substep * 1e-3) : 0.0;
  r.neighbors_mean = s.neighbors_mean;
  r.neighbors_max = s.neighbors_max;
  r.bytes_per_particle = (double)s.memory_bytes / count;
  for (int k = 0; k < SPH_STAGE_COUNT; ++k)
    r.stage_ms_per_substep[k] = substeps_total ? stage_sum[k] / (double)substeps_total : 0.0;
  r.density_error_mean = (s.density_mean - def.rest_density) / def.rest_density;
  r.density_min = s.density_min;
  r.pressure_iterations = substeps_total ? (double)pressure_iterations / (double)substeps_total : 0.0;
  r.divergence_iterations = substeps_total ? (double)divergence_iterations / (double)substeps_total : 0.0;
  r.density_max = s.density_max;
  r.max_speed = s.max_speed;
  free(frame_ms);
  free(substep_ms);
  check(sph_world_destroy(world), "sph_world_destroy");
  check(sph_context_destroy(context), "sph_context_destroy");
  return r;
}

static void print_result(const result* r, const options* o) {
  double total = 0.0;
  for (int k = 0; k < SPH_STAGE_COUNT; ++k) total += r->stage_ms_per_substep[k];
  printf("\n%s sphere, %s backend, option %s, %u particles, %d frames of %.0f ms after %d warm-up\n",
         r->scene, r->backend, r->option, r->count, o->frames, FRAME_DT * 1e3, o->warmup);
  printf("  %-28s %12.4f\n", "s/frame (median)", r->ms_per_frame * 1e-3);
  printf("  %-28s %12u\n", "substeps/frame", r->substeps_per_frame);
  printf("  %-28s %12.4f\n", "ms/substep (median)", r->ms_per_substep);
  printf("  %-28s %12.4g\n", "particle-substeps/s", r->particle_substeps_per_s);
  printf("  %-28s %12.2f (max %u)\n", "neighbours/particle", r->neighbors_mean, r->neighbors_max);
  printf("  %-28s %12.1f\n", "bytes/particle", r->bytes_per_particle);
  printf("  %-28s %12.3g (min %.2f, max %.2f kg/m^3)\n", "end mean density error", r->density_error_mean,
         r->density_min, r->density_max);
  printf("  %-28s %12.4g m/s\n", "end max speed", r->max_speed);
  if (strcmp(r->option, "dfsph") == 0) {
    /* Neighbour passes: density and factor, the non-pressure forces, and per solve the warm
       start's velocity update and residual plus two per iteration (as bench/solver_front). */
    printf("  %-28s %12.2f density, %.2f divergence\n", "DFSPH iterations/substep", r->pressure_iterations,
           r->divergence_iterations);
    printf("  %-28s %12.2f\n", "neighbour passes/substep",
           6.0 + 2.0 * (r->pressure_iterations + r->divergence_iterations));
  }
  printf("  stage breakdown (ms per substep, share):\n");
  for (int k = 0; k < SPH_STAGE_COUNT; ++k)
    printf("    %-14s %10.4f  %5.1f%%\n", support_stage_name(k), r->stage_ms_per_substep[k],
           total > 0 ? 100.0 * r->stage_ms_per_substep[k] / total : 0.0);
  fflush(stdout);
}

static void write_json(const char* path, const result* rs, int n, const options* o) {
  FILE* f = fopen(path, "w");
  if (!f) {
    fprintf(stderr, "rest_sphere: cannot write %s\n", path);
    exit(1);
  }
  fprintf(f, "[\n");
  for (int i = 0; i < n; ++i) {
    const result* r = &rs[i];
    fprintf(
        f,
        "  {\"benchmark\": \"rest_sphere\", \"label\": \"%s\", \"scene\": \"%s\", \"option\": \"%s\", "
        "\"backend\": \"%s\", "
        "\"particles\": %u, \"frames\": %d, \"warmup\": %d, \"frame_dt\": %.3f, \"substeps_per_frame\": %u, "
        "\"s_per_frame\": %.6g, \"ms_per_substep\": %.6g, \"particle_substeps_per_s\": %.6g, "
        "\"neighbors_mean\": %.4f, \"neighbors_max\": %u, \"bytes_per_particle\": %.2f, "
        "\"density_error_mean\": %.6g, \"density_min\": %.3f, \"density_max\": %.3f, \"max_speed\": %.6g, "
        "\"stage_ms_per_substep\": {",
        o->label ? o->label : "", r->scene, r->option, r->backend, r->count, o->frames, o->warmup, FRAME_DT,
        r->substeps_per_frame, r->ms_per_frame * 1e-3, r->ms_per_substep, r->particle_substeps_per_s,
        r->neighbors_mean, r->neighbors_max, r->bytes_per_particle, r->density_error_mean, r->density_min,
        r->density_max, r->max_speed);
    for (int k = 0; k < SPH_STAGE_COUNT; ++k)
      fprintf(f, "\"%s\": %.6g%s", support_stage_name(k), r->stage_ms_per_substep[k],
              k + 1 < SPH_STAGE_COUNT ? ", " : "");
    fprintf(f, "}}%s\n", i + 1 < n ? "," : "");
  }
  fprintf(f, "]\n");
  fclose(f);
}

static void append_csv(const char* path, const result* rs, int n, const options* o) {
  FILE* probe = fopen(path, "r");
  const int exists = probe != NULL;
  if (probe) fclose(probe);
  FILE* f = fopen(path, "a");
  if (!f) {
    fprintf(stderr, "rest_sphere: cannot write %s\n", path);
    exit(1);
  }
  if (!exists) {
    fprintf(f,
            "label,scene,option,backend,particles,frames,substeps_per_frame,s_per_frame,ms_per_substep,"
            "particle_substeps_per_s,neighbors_mean,bytes_per_particle,density_error_mean,max_speed");
    for (int k = 0; k < SPH_STAGE_COUNT; ++k) fprintf(f, ",ms_%s", support_stage_name(k));
    fprintf(f, "\n");
  }
  for (int i = 0; i < n; ++i) {
    const result* r = &rs[i];
    fprintf(f, "%s,%s,%s,%s,%u,%d,%u,%.6g,%.6g,%.6g,%.4f,%.2f,%.6g,%.6g", o->label ? o->label : "", r->scene,
            r->option, r->backend, r->count, o->frames, r->substeps_per_frame, r->ms_per_frame * 1e-3,
            r->ms_per_substep, r->particle_substeps_per_s, r->neighbors_mean, r->bytes_per_particle,
            r->density_error_mean, r->max_speed);
    for (int k = 0; k < SPH_STAGE_COUNT; ++k) fprintf(f, ",%.6g", r->stage_ms_per_substep[k]);
    fprintf(f, "\n");
  }
  fclose(f);
}

static void usage(void) {
  fprintf(stderr,
          "usage: rest_sphere [--particles N|largest] [--frames F] [--warmup W] [--backend cpu|cuda|auto]\n"
          "                   [--case rest|moving|both] [--option "
          "none|surface_tension|normalized_density|density_diffusion|\n"
          "                   clavet|tait|rk4|acoustic_limit|springs|dfsph] [--json FILE] [--csv FILE]\n"
          "                   [--label TEXT] [--cuda-frames graph|stream] [--density-block N]\n"
          "                   [--force-block N] [--particle-lanes N] [--threads N] [--dfsph-masks "
          "on|off|lists]\n");
  exit(2);
}

int main(int argc, char** argv) {
  options o = {100000, 0, "none", 100, 3, SPH_BACKEND_AUTO, "both", NULL, NULL, NULL, SPH_CUDA_FRAMES_GRAPH,
               0,      0, 0,      0,   0};
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!v) usage();
    if (strcmp(a, "--particles") == 0) {
      o.largest = strcmp(v, "largest") == 0;
      o.particles = o.largest ? 100 : (uint32_t)strtoul(v, NULL, 10);
    } else if (strcmp(a, "--option") == 0) {
      o.option = v;
    } else if (strcmp(a, "--frames") == 0) {
      o.frames = atoi(v);
    } else if (strcmp(a, "--warmup") == 0) {
      o.warmup = atoi(v);
    } else if (strcmp(a, "--backend") == 0) {
      o.backend = support_backend_from_name(v, SPH_BACKEND_AUTO);
    } else if (strcmp(a, "--case") == 0) {
      o.which = v;
    } else if (strcmp(a, "--json") == 0) {
      o.json = v;
    } else if (strcmp(a, "--csv") == 0) {
      o.csv = v;
    } else if (strcmp(a, "--label") == 0) {
      o.label = v;
    } else if (strcmp(a, "--cuda-frames") == 0) {
      if (strcmp(v, "graph") != 0 && strcmp(v, "stream") != 0) usage();
      o.cuda_frames = strcmp(v, "stream") == 0 ? SPH_CUDA_FRAMES_STREAM : SPH_CUDA_FRAMES_GRAPH;
    } else if (strcmp(a, "--density-block") == 0) {
      o.density_block = (uint32_t)strtoul(v, NULL, 10);
    } else if (strcmp(a, "--force-block") == 0) {
      o.force_block = (uint32_t)strtoul(v, NULL, 10);
    } else if (strcmp(a, "--particle-lanes") == 0) {
      o.particle_lanes = (uint32_t)strtoul(v, NULL, 10);
    } else if (strcmp(a, "--threads") == 0) {
      o.threads = (uint32_t)strtoul(v, NULL, 10);
    } else if (strcmp(a, "--dfsph-masks") == 0) {
      if (strcmp(v, "on") != 0 && strcmp(v, "off") != 0 && strcmp(v, "lists") != 0) usage();
      o.dfsph_masks = strcmp(v, "off") == 0     ? SPH_CUDA_DFSPH_MASKS_OFF
                      : strcmp(v, "lists") == 0 ? SPH_CUDA_DFSPH_NEIGHBOR_LISTS
                                                : 0u;
    } else {
      usage();
    }
    ++i;
  }
  if (o.particles < 100 || o.frames < 1 || o.warmup < 0) usage();
  result results[2];
  int n = 0;
  if (strcmp(o.which, "moving") != 0) results[n++] = run_case(&o, 0);
  if (strcmp(o.which, "rest") != 0) results[n++] = run_case(&o, 1);
  for (int i = 0; i < n; ++i) print_result(&results[i], &o);
  if (o.json) write_json(o.json, results, n, &o);
  if (o.csv) append_csv(o.csv, results, n, &o);
  return 0;
}
