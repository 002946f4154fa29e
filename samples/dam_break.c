/* The default demo scene, a dam break, built through the C API alone as an engine would
 * (the same scene as samples/scenes/dam_break.json, which sph-run plays): a column of water
 * collapses in a closed tank, an inverted box collider. Every frame's particles are written as
 * CSV (id, x, y, z, vx, vy, vz, density) to the output directory.
 *
 * Usage: dam_break [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/dam_break_c, 120 frames at 60 fps) */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "sph_c.h"

static int failed(sph_result r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "dam_break: %s failed: %s\n  %s\n", what, sph_result_string(r), sph_get_last_error());
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

/* Copies the particles out and writes DIR/frame_NNNN.csv through a temporary name. */
static int write_frame(const sph_world* world, const char* dir, int frame) {
  char path[4200], tmp[4300];
  uint32_t n = 0, i;
  float *x = NULL, *v = NULL, *rho = NULL;
  uint32_t* id = NULL;
  FILE* f = NULL;
  int status = 1;
  if (failed(sph_world_get_particle_count(world, &n), "sph_world_get_particle_count")) return 1;
  x = malloc(12 * (size_t)n + 12);
  v = malloc(12 * (size_t)n + 12);
  rho = malloc(4 * (size_t)n + 4);
  id = malloc(4 * (size_t)n + 4);
  if (!x || !v || !rho || !id) goto done;
  if (n > 0 &&
      (failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, x, 12ull * n, 0, 0, n, NULL), "copy") ||
       failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, v, 12ull * n, 0, 0, n, NULL), "copy") ||
       failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, rho, 4ull * n, 0, 0, n, NULL), "copy") ||
       failed(sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, id, 4ull * n, 0, 0, n, NULL), "copy")))
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
  if (status) fprintf(stderr, "dam_break: cannot write frame %d to %s\n", frame, dir);
  free(x);
  free(v);
  free(rho);
  free(id);
  return status;
}

int main(int argc, char** argv) {
  const char* out_dir = "out/dam_break_c";
  int frames = 120, frame, i, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc tank_shape;
  sph_collider_def tank;
  sph_collider_id tank_id;
  sph_fill_box_desc column;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_sdf* tank_sdf = NULL;
  sph_stats stats;
  uint32_t count = 0;

  for (i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      const char* b = argv[++i];
      backend = strcmp(b, "cpu") == 0    ? SPH_BACKEND_CPU
                : strcmp(b, "cuda") == 0 ? SPH_BACKEND_CUDA
                                         : SPH_BACKEND_AUTO;
    } else if (argv[i][0] != '-') {
      out_dir = argv[i];
    } else {
      fprintf(stderr, "usage: dam_break [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]\n");
      return 2;
    }
  }
  if (make_dirs(out_dir) != 0) {
    fprintf(stderr, "dam_break: cannot create %s: %s\n", out_dir, strerror(errno));
    return 1;
  }

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;

  sph_world_def_init(&world_def); /* water at 2 cm */
  world_def.capacity = 20000;
  world_def.particle_spacing = 0.02f;
  if (failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params); /* gravity -9.81 y, k = 100, mu = 1, dt_max = 1 ms: the defaults */
  if (failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;

  /* The tank: a box SDF whose interior is 1 m x 0.6 m x 0.3 m, inverted so that the fluid stays
   * inside it. The floor is at y = 0. */
  sph_shape_desc_init(&tank_shape);
  tank_shape.shape = SPH_SHAPE_BOX;
  tank_shape.half_extents.x = 0.5f;
  tank_shape.half_extents.y = 0.3f;
  tank_shape.half_extents.z = 0.15f;
  tank_shape.voxel_size = 0.01f;
  if (failed(sph_sdf_create_shape(context, &tank_shape, &tank_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&tank);
  tank.sdf = tank_sdf;
  tank.flags = SPH_COLLIDER_FLAG_INVERTED;
  tank.transform = sph_transform_identity();
  tank.transform.position.y = 0.3f;
  if (failed(sph_collider_create(world, &tank, &tank_id), "sph_collider_create")) goto done;

  /* The water column against the left wall. */
  sph_fill_box_desc_init(&column);
  column.min.x = -0.5f;
  column.min.y = 0.0f;
  column.min.z = -0.15f;
  column.max.x = -0.15f;
  column.max.y = 0.5f;
  column.max.z = 0.15f;
  if (failed(sph_world_fill_box(world, &column, &count), "sph_world_fill_box")) goto done;

  printf("dam_break: %u particles, %d frames -> %s/\n", count, frames, out_dir);
  if (write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    if (failed(sph_world_step(world, 1.0f / 60.0f), "sph_world_step")) goto done;
    if (write_frame(world, out_dir, frame)) goto done;
    sph_stats_init(&stats);
    sph_world_get_stats(world, &stats);
    if (frame % 30 == 0 || frame == frames)
      printf("frame %3d/%d  substeps %3u  max speed %5.2f m/s  %6.1f ms\n", frame, frames, stats.substeps,
             stats.max_speed, stats.step_ms);
  }
  status = 0;

done:
  sph_sdf_destroy(tank_sdf); /* the collider keeps its own reference */
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
