// SPDX-License-Identifier: MIT
/*
 * dam_break - BENCHMARK.md case 2, the realistic load: a water column of width a, height 2a and
 * depth a at one end of a tank 5a long, gravity, the tank a collider (an inverted hollow-box
 * SDF), library defaults otherwise. The spacing is chosen so the column holds about
 * --particles particles. Uses only the public C API; the tank and column are tests/support's
 * support_dam_break.
 *
 *   dam_break [--particles N] [--seconds S] [--backend cpu|cuda|auto] [--width A]
 *             [--json FILE] [--front-csv FILE] [--label TEXT]
 *
 * Prints the figures of case 1 (time per frame and per substep, particle-substeps/s, neighbours,
 * bytes per particle, stage shares), all from the frames after the first (the first builds the
 * collider's device copy), and the surge front (the largest x of any particle, from the
 * column's wall) against time in the Martin & Moyce (1952) variables T = t sqrt(2 g / a),
 * Z = x / a. The accuracy of that front is tests/validation's business; here it shows that the
 * timed run did what a dam break does.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph_c.h"
#include "support.h"

#define FRAME_DT 0.04f /* 25 frames per second */
#define GRAVITY 9.81f

static void check(sph_result r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "dam_break: %s failed: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
    exit(1);
  }
}

static int compare_double(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

static void usage(void) {
  fprintf(stderr,
          "usage: dam_break [--particles N] [--seconds S] [--backend cpu|cuda|auto] [--width A]\n"
          "                 [--json FILE] [--front-csv FILE] [--label TEXT]\n");
  exit(2);
}

int main(int argc, char** argv) {
  double wanted = 100000.0, seconds = 1.0, a = 0.5;
  sph_backend backend = SPH_BACKEND_AUTO;
  const char *json = NULL, *front_csv = NULL, *label = "";
  for (int i = 1; i < argc; i += 2) {
    const char* v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!v) usage();
    if (strcmp(argv[i], "--particles") == 0)
      wanted = atof(v);
    else if (strcmp(argv[i], "--seconds") == 0)
      seconds = atof(v);
    else if (strcmp(argv[i], "--width") == 0)
      a = atof(v);
    else if (strcmp(argv[i], "--backend") == 0)
      backend = support_backend_from_name(v, SPH_BACKEND_AUTO);
    else if (strcmp(argv[i], "--json") == 0)
      json = v;
    else if (strcmp(argv[i], "--front-csv") == 0)
      front_csv = v;
    else if (strcmp(argv[i], "--label") == 0)
      label = v;
    else
      usage();
  }
  if (wanted < 1000 || seconds <= 2 * FRAME_DT || a <= 0) usage();
  const int frames = (int)ceil(seconds / FRAME_DT);
  /* An FCC lattice holds sqrt(2) / s^3 particles per cubic metre. */
  const double column_volume = a * 2.0 * a * a;
  const float spacing = (float)cbrt(sqrt(2.0) * column_volume / wanted);

  sph_context* context = NULL;
  check(support_context_create(backend, &context), "sph_context_create");
  sph_backend resolved;
  check(sph_context_get_backend(context, &resolved), "sph_context_get_backend");

  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = spacing;
  def.capacity = (uint32_t)(1.2 * wanted) + 1000u;
  sph_world* world = NULL;
  check(sph_world_create(context, &def, &world), "sph_world_create");
  /* The tank's cavity: x in [0, 5a], y in [0, 3a], z in [0, a]; the column [0, a] x [0, 2a] x
   * [0, a] against its x = 0 wall. */
  const sph_vec3 half = {(float)(2.5 * a), (float)(1.5 * a), (float)(0.5 * a)};
  const support_tank tank = {half, half, spacing, 0.0f};
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f};
  const sph_vec3 column_max = {(float)a, (float)(2.0 * a), (float)a};
  uint32_t count = 0;
  check(support_dam_break(context, world, &tank, column_min, column_max, NULL, NULL, &count),
        "support_dam_break");

  FILE* front = front_csv ? fopen(front_csv, "w") : NULL;
  if (front_csv && !front) {
    fprintf(stderr, "dam_break: cannot write %s\n", front_csv);
    return 1;
  }
  if (front) fprintf(front, "t,T,front_x,Z\n");
  float* positions = malloc(sizeof(float) * 3 * (size_t)count);
  double* frame_ms = malloc(sizeof(double) * (size_t)frames);
  double* substep_ms = malloc(sizeof(double) * (size_t)frames);
  if (!positions || !frame_ms || !substep_ms) {
    fprintf(stderr, "dam_break: out of host memory\n");
    return 1;
  }
  double stage_sum[SPH_STAGE_COUNT] = {0}, neighbors_sum = 0.0;
  uint64_t substeps_total = 0;
  sph_stats s;
  sph_stats_init(&s);
  int timed = 0;
  printf("dam break: %u particles at spacing %.4g m, a = %.3g m, %s backend, %d frames of %.0f ms\n", count,
         spacing, a, resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu", frames, FRAME_DT * 1e3);
  printf("%8s %8s %10s %8s %10s\n", "t (s)", "T", "front (m)", "Z", "ms/frame");
  for (int f = 0; f < frames; ++f) {
    const sph_result r = sph_world_step(world, FRAME_DT);
    check(r, "sph_world_step");
    check(sph_world_get_stats(world, &s), "sph_world_get_stats");
    uint32_t n = 0;
    check(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, positions,
                                   sizeof(float) * 3 * (size_t)count, 0, 0, count, &n),
          "sph_world_copy_attribute");
    float x_max = 0.0f;
    for (uint32_t i = 0; i < n; ++i) x_max = positions[3 * i] > x_max ? positions[3 * i] : x_max;
    const double t = s.simulated_time, T = t * sqrt(2.0 * GRAVITY / a), Z = x_max / a;
    printf("%8.3f %8.3f %10.4f %8.3f %10.2f\n", t, T, x_max, Z, s.step_ms);
    if (front) fprintf(front, "%.5f,%.5f,%.6f,%.5f\n", t, T, x_max, Z);
    if (f == 0) continue; /* the first frame uploads the collider: not the steady cost */
    frame_ms[timed] = s.step_ms;
    substep_ms[timed] = s.substeps ? s.step_ms / s.substeps : 0.0;
    ++timed;
    substeps_total += s.substeps;
    neighbors_sum += s.neighbors_mean;
    for (int k = 0; k < SPH_STAGE_COUNT; ++k) stage_sum[k] += s.stage_ms[k];
  }
  if (front) fclose(front);
  qsort(frame_ms, (size_t)timed, sizeof(double), compare_double);
  qsort(substep_ms, (size_t)timed, sizeof(double), compare_double);
  const double ms_frame = frame_ms[timed / 2], ms_substep = substep_ms[timed / 2];
  double stage_total = 0.0;
  for (int k = 0; k < SPH_STAGE_COUNT; ++k) stage_total += stage_sum[k];
  printf("\n  %-28s %12.4f\n", "s/frame (median)", ms_frame * 1e-3);
  printf("  %-28s %12.1f\n", "substeps/frame (mean)", (double)substeps_total / timed);
  printf("  %-28s %12.4f\n", "ms/substep (median)", ms_substep);
  printf("  %-28s %12.4g\n", "particle-substeps/s", count / (ms_substep * 1e-3));
  printf("  %-28s %12.2f\n", "neighbours/particle (mean)", neighbors_sum / timed);
  printf("  %-28s %12.1f\n", "bytes/particle", (double)s.memory_bytes / count);
  printf("  stage shares:");
  for (int k = 0; k < SPH_STAGE_COUNT; ++k)
    printf(" %s %.1f%%", support_stage_name(k), stage_total > 0 ? 100.0 * stage_sum[k] / stage_total : 0.0);
  printf("\n");
  if (json) {
    FILE* j = fopen(json, "w");
    if (!j) {
      fprintf(stderr, "dam_break: cannot write %s\n", json);
      return 1;
    }
    fprintf(j,
            "[{\"benchmark\": \"dam_break\", \"label\": \"%s\", \"backend\": \"%s\", \"particles\": %u, "
            "\"spacing\": %.6g, \"width\": %.4g, \"frames\": %d, \"s_per_frame\": %.6g, \"ms_per_substep\": "
            "%.6g, "
            "\"substeps_per_frame\": %.3f, \"particle_substeps_per_s\": %.6g, \"neighbors_mean\": %.4f, "
            "\"bytes_per_particle\": %.2f, \"stage_ms_per_substep\": {",
            label, resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu", count, spacing, a, frames, ms_frame * 1e-3,
            ms_substep, (double)substeps_total / timed, count / (ms_substep * 1e-3), neighbors_sum / timed,
            (double)s.memory_bytes / count);
    for (int k = 0; k < SPH_STAGE_COUNT; ++k)
      fprintf(j, "\"%s\": %.6g%s", support_stage_name(k),
              substeps_total ? stage_sum[k] / (double)substeps_total : 0.0,
              k + 1 < SPH_STAGE_COUNT ? ", " : "");
    fprintf(j, "}}]\n");
    fclose(j);
  }
  free(positions);
  free(frame_ms);
  free(substep_ms);
  check(sph_world_destroy(world), "sph_world_destroy");
  check(sph_context_destroy(context), "sph_context_destroy");
  return 0;
}
