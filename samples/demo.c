// SPDX-License-Identifier: MIT
/* The default demo scene: two droplets of water, 12 cm across, collide head-on at 1.5 m/s
 * in zero gravity and splash. Every frame's particles are written as CSV
 * (id, x, y, z, vx, vy, vz, density, pressure) to the output directory, built through the
 * C API alone, as an engine would.
 *
 * Usage: demo [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]  (default out/demo, 90 frames) */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sample_io.h"
#include "sph_c.h"

/* Writes one frame to DIR/frame_NNNN.csv through a temporary name, so an interrupted run
 * leaves only complete frames. */
static int write_frame(sph_world* world, const char* dir, int frame, float* vec, float* scalar,
                       uint32_t* ids) {
  char path[4200], tmp[4300];
  uint32_t n = 0, i;
  float *pos = vec, *vel = vec + 0, *rho = scalar, *p = scalar;
  FILE* f;
  sph_world_get_particle_count(world, &n);
  pos = vec;
  vel = vec + 3 * (size_t)n;
  rho = scalar;
  p = scalar + n;
  if (sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, pos, 12ull * n, 0, 0, n, NULL),
                    "copy") ||
      sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, vel, 12ull * n, 0, 0, n, NULL),
                    "copy") ||
      sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, rho, 4ull * n, 0, 0, n, NULL),
                    "copy") ||
      sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_PRESSURE, p, 4ull * n, 0, 0, n, NULL),
                    "copy") ||
      sample_failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, ids, 4ull * n, 0, 0, n, NULL), "copy"))
    return 1;
  snprintf(path, sizeof path, "%s/frame_%04d.csv", dir, frame);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  f = fopen(tmp, "w");
  if (!f) {
    fprintf(stderr, "demo: cannot write %s: %s\n", tmp, strerror(errno));
    return 1;
  }
  fprintf(f, "id,x,y,z,vx,vy,vz,density,pressure\n");
  for (i = 0; i < n; ++i)
    fprintf(f, "%u,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", ids[i], pos[3 * i], pos[3 * i + 1],
            pos[3 * i + 2], vel[3 * i], vel[3 * i + 1], vel[3 * i + 2], rho[i], p[i]);
  if (fclose(f) != 0 || rename(tmp, path) != 0) {
    fprintf(stderr, "demo: cannot finish %s\n", path);
    return 1;
  }
  return 0;
}

int main(int argc, char** argv) {
  const char* out_dir = "out/demo";
  int frames = 90, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  sph_fill_sphere_desc drop;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_stats stats;
  uint32_t count = 0, added = 0;
  float *vec = NULL, *scalar = NULL;
  uint32_t* ids = NULL;
  sph_backend used;

  status = sample_parse_args(argc, argv, "demo", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;
  if (frames < 1) frames = 1;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;
  sph_context_get_backend(context, &used);

  sph_world_def_init(&world_def); /* water at 1 cm spacing */
  world_def.particle_spacing = 0.01f;
  world_def.capacity = 40000;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;

  sph_world_params_init(&params);
  params.gravity.x = params.gravity.y = params.gravity.z = 0.0f;
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  sph_fill_sphere_desc_init(&drop);
  drop.radius = 0.06f;
  drop.center.x = -0.08f;
  drop.velocity.x = 1.5f;
  if (sample_failed(sph_world_fill_sphere(world, &drop, &added), "sph_world_fill_sphere")) goto done;
  count += added;
  drop.center.x = 0.08f;
  drop.center.y = 0.03f; /* off-centre, so the splash turns */
  drop.velocity.x = -1.5f;
  if (sample_failed(sph_world_fill_sphere(world, &drop, &added), "sph_world_fill_sphere")) goto done;
  count += added;

  vec = malloc(sizeof(float) * 6 * count);
  scalar = malloc(sizeof(float) * 2 * count);
  ids = malloc(sizeof(uint32_t) * count);
  if (!vec || !scalar || !ids) {
    fprintf(stderr, "demo: out of memory\n");
    goto done;
  }
  printf("demo: two droplets, %u particles, %s backend, %d frames -> %s/\n", count,
         used == SPH_BACKEND_CUDA ? "CUDA" : "CPU", frames, out_dir);
  if (write_frame(world, out_dir, 0, vec, scalar, ids)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    if (sample_failed(sph_world_step(world, 1.0f / 60.0f), "sph_world_step")) goto done;
    if (write_frame(world, out_dir, frame, vec, scalar, ids)) goto done;
    sph_stats_init(&stats);
    sph_world_get_stats(world, &stats);
    if (frame % 10 == 0 || frame == frames)
      printf("frame %3d/%d  substeps %3u  max speed %5.2f m/s  density %6.1f..%6.1f kg/m^3  %6.1f ms\n",
             frame, frames, stats.substeps, stats.max_speed, stats.density_min, stats.density_max,
             stats.step_ms);
  }
  printf("demo: wrote %d frames (CSV: id,x,y,z,vx,vy,vz,density,pressure) to %s/\n", frames + 1, out_dir);
  status = 0;

done:
  free(vec);
  free(scalar);
  free(ids);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
