// SPDX-License-Identifier: MIT
/* The speed-accuracy trade (../shared/BENCHMARK.md case 4): the dam break of Martin & Moyce
 * (tests/support/dam_break.c) for integrator (symplectic Euler, RK4) x step factor lambda
 * (0.1, 0.2, 0.4, 0.8) x three resolutions. For each run: the surge front's error against the
 * measurements (mean and worst over T in [0.8, 3.3], with and without the one fitted time
 * shift), the mean compression (density error) and the wall seconds per simulated second.
 *
 *   speed_accuracy [--backend cpu|cuda|auto] [--layers 10,20,40] [--out results.csv]
 *
 * --layers: lattice layers across the column width (the resolution; particles grow as its
 * square, substeps linearly). Writes a CSV (one row per run) and prints a table; the plot of
 * error against cost is bench/speed_accuracy_plot.py (scripts/validate runs both). A run that
 * fails (an unstable step: SPH_ERROR_NON_FINITE) is a row with status "failed" and no numbers. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dam_break.h"
#include "sph_c.h"
#include "support.h"

#define MAX_RESOLUTIONS 8

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

int main(int argc, char** argv) {
  const float factors[4] = {0.1f, 0.2f, 0.4f, 0.8f};
  const sph_integrator integrators[2] = {SPH_INTEGRATOR_SYMPLECTIC_EULER, SPH_INTEGRATOR_RK4};
  uint32_t layers[MAX_RESOLUTIONS] = {10, 20, 40};
  int resolutions = 3;
  const char* out_path = "speed_accuracy.csv";
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context* context = NULL;
  sph_backend resolved = SPH_BACKEND_CPU;
  dam_break_result* result = (dam_break_result*)malloc(sizeof(dam_break_result));
  FILE* csv;
  if (!result) return 1;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      const char* b = argv[++i];
      backend = support_backend_from_name(b, SPH_BACKEND_AUTO);
    } else if (strcmp(argv[i], "--layers") == 0 && i + 1 < argc) {
      resolutions = parse_layers(argv[++i], layers);
      if (resolutions == 0) {
        fprintf(stderr, "speed_accuracy: --layers takes a comma-separated list of integers in [4, 1000]\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      out_path = argv[++i];
    } else {
      fprintf(stderr,
              "usage: speed_accuracy [--backend cpu|cuda|auto] [--layers 10,20,40] [--out results.csv]\n");
      return 2;
    }
  }
  if (support_context_create(backend, &context) != SPH_OK) {
    fprintf(stderr, "speed_accuracy: %s\n", sph_get_last_error());
    return 1;
  }
  sph_context_get_backend(context, &resolved);
  csv = fopen(out_path, "w");
  if (!csv) {
    fprintf(stderr, "speed_accuracy: cannot write %s\n", out_path);
    return 1;
  }
  fprintf(csv,
          "backend,integrator,step_factor,layers,particles,spacing_m,substeps,wall_s,simulated_s,wall_s_per_"
          "simulated_s,"
          "shift_T,mean_error,max_error,mean_error_unshifted,max_error_unshifted,mean_compression,max_"
          "compression,"
          "status\n");
  printf("sph %s\n%s backend; dam break of Martin & Moyce (1952), errors over T in [%.1f, %.1f]\n\n",
         sph_get_build_info(), resolved == SPH_BACKEND_CUDA ? "CUDA" : "CPU", DAM_BREAK_T_FIRST,
         DAM_BREAK_T_LAST);
  printf("%-16s %-6s %-6s %-9s %-9s %-10s %-7s %-8s %-8s %-9s %-8s\n", "integrator", "lambda", "layers",
         "particles", "substeps", "wall s/s", "shift", "mean err", "max err", "unshifted", "compr.");
  for (int r = 0; r < resolutions; ++r)
    for (int g = 0; g < 2; ++g)
      for (int f = 0; f < 4; ++f) {
        dam_break_config config;
        const char* name = integrators[g] == SPH_INTEGRATOR_RK4 ? "rk4" : "symplectic_euler";
        sph_result status;
        dam_break_config_default(&config, layers[r]);
        config.integrator = integrators[g];
        config.step_factor = factors[f];
        status = dam_break_run(context, &config, result, NULL, NULL);
        if (status != SPH_OK) {
          printf("%-16s %-6.2f %-6u failed: %s\n", name, factors[f], layers[r], result->message);
          fprintf(csv, "%s,%s,%.2f,%u,%u,,,,,,,,,,,,,failed\n", resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu",
                  name, factors[f], layers[r], result->particles);
          fflush(csv);
          continue;
        }
        {
          const double cost = result->wall_seconds / result->simulated_seconds;
          printf("%-16s %-6.2f %-6u %-9u %-9llu %-10.2f %+-7.3f %-8.2f %-8.2f %-9.2f %-8.2f\n", name,
                 factors[f], layers[r], result->particles, (unsigned long long)result->substeps, cost,
                 result->shift_T, 100.0 * result->mean_error, 100.0 * result->max_error,
                 100.0 * result->mean_error_unshifted, 100.0 * result->mean_compression);
          fprintf(csv, "%s,%s,%.2f,%u,%u,%.6g,%llu,%.6g,%.6g,%.6g,%.4f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,ok\n",
                  resolved == SPH_BACKEND_CUDA ? "cuda" : "cpu", name, factors[f], layers[r],
                  result->particles, result->spacing, (unsigned long long)result->substeps,
                  result->wall_seconds, result->simulated_seconds, cost, result->shift_T, result->mean_error,
                  result->max_error, result->mean_error_unshifted, result->max_error_unshifted,
                  result->mean_compression, result->max_compression);
          fflush(csv);
        }
      }
  fclose(csv);
  printf("\nwrote %s\n", out_path);
  free(result);
  sph_context_destroy(context);
  return 0;
}
