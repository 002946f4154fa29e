// SPDX-License-Identifier: MIT
#include "sample_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "support.h"

static const char* sample_name = "sample";

int sample_failed(sph_result r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "%s: %s failed: %s\n  %s\n", sample_name, what, sph_result_string(r),
            sph_get_last_error());
    return 1;
  }
  return 0;
}

static int make_dirs(const char* path) {
  char buf[4096];
  size_t i, n = strlen(path);
  if (n >= sizeof buf) return -1;
  memcpy(buf, path, n + 1);
  for (i = 1; i <= n; ++i) {
    if (buf[i] == '/' || buf[i] == '\0') {
      char saved = buf[i];
      buf[i] = '\0';
      if (mkdir(buf, 0755) != 0 && errno != EEXIST) return -1;
      buf[i] = saved;
    }
  }
  return 0;
}

int sample_parse_args(int argc, char** argv, const char* name, const char** out_dir, int* frames,
                      sph_backend* backend) {
  int i;
  sample_name = name;
  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      /* a whole positive number: "abc" or "-5" used to run 0 frames and report success */
      char* end = NULL;
      long value;
      errno = 0;
      value = strtol(argv[++i], &end, 10);
      if (errno != 0 || end == argv[i] || *end != '\0' || value < 1 || value > 1000000) {
        fprintf(stderr, "%s: --frames %s: expected a whole number from 1 to 1000000\n", name, argv[i]);
        return 2;
      }
      *frames = (int)value;
    } else if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      /* an unknown name used to fall back to auto silently */
      *backend = support_backend_from_name(argv[++i], SPH_BACKEND_FORCE32);
      if (*backend == SPH_BACKEND_FORCE32) {
        fprintf(stderr, "%s: --backend %s: expected auto, cpu or cuda\n", name, argv[i]);
        return 2;
      }
    } else if (argv[i][0] != '-') {
      *out_dir = argv[i];
    } else {
      fprintf(stderr, "usage: %s [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]\n", name);
      return 2;
    }
  }
  if (make_dirs(*out_dir) != 0) {
    fprintf(stderr, "%s: cannot create %s: %s\n", name, *out_dir, strerror(errno));
    return 1;
  }
  return 0;
}

int sample_write_frame(const sph_world* world, const char* dir, int frame) {
  char path[4200], tmp[4300];
  uint32_t n = 0, i;
  float *x = NULL, *v = NULL, *rho = NULL;
  uint32_t* id = NULL;
  FILE* f = NULL;
  int status = 1;
  if (sample_failed(sph_world_get_particle_count(world, &n), "sph_world_get_particle_count")) return 1;
  x = malloc(12 * (size_t)n + 12);
  v = malloc(12 * (size_t)n + 12);
  rho = malloc(4 * (size_t)n + 4);
  id = malloc(4 * (size_t)n + 4);
  if (!x || !v || !rho || !id) goto done;
  if (n > 0 &&
      (sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, x, 12ull * n, 0, 0, n, NULL),
                     "copy") ||
       sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, v, 12ull * n, 0, 0, n, NULL),
                     "copy") ||
       sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, rho, 4ull * n, 0, 0, n, NULL),
                     "copy") ||
       sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, id, 4ull * n, 0, 0, n, NULL), "copy")))
    goto done;
  snprintf(path, sizeof path, "%s/frame_%04d.csv", dir, frame);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  f = fopen(tmp, "w");
  if (!f) goto done;
  fprintf(f, "id,x,y,z,vx,vy,vz,density\n");
  for (i = 0; i < n; ++i)
    fprintf(f, "%u,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g\n", id[i], x[3 * i], x[3 * i + 1], x[3 * i + 2],
            v[3 * i], v[3 * i + 1], v[3 * i + 2], rho[i]);
  status = fclose(f) != 0 || rename(tmp, path) != 0;
done:
  if (status) fprintf(stderr, "%s: cannot write frame %d to %s\n", sample_name, frame, dir);
  free(x);
  free(v);
  free(rho);
  free(id);
  return status;
}

int sample_step_and_write(sph_world* world, const char* dir, int frame, int frames) {
  sph_stats stats;
  if (sample_failed(sph_world_step(world, 1.0f / 60.0f), "sph_world_step")) return 1;
  if (sample_write_frame(world, dir, frame)) return 1;
  sph_stats_init(&stats);
  sph_world_get_stats(world, &stats);
  if (frame % 30 == 0 || frame == frames)
    printf("frame %3d/%d  %6u particles  substeps %3u  max speed %5.2f m/s  %7.1f ms\n", frame, frames,
           stats.particle_count, stats.substeps, stats.max_speed, stats.step_ms);
  return 0;
}
