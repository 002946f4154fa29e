// SPDX-License-Identifier: MIT
/*
 * boundary_map_rebuild - what the walls in the density (SPH_FEATURE_BOUNDARY_DENSITY) cost when a
 * collider's SDF changes: each sph_sdf_update of an asset makes the next step recompute its
 * boundary map (docs/physics.md, "Cost and memory"), so a deforming collider pays a map a frame.
 * A solid box of half side H at voxel V (sph_sdf_create_shape), a small block of water resting on
 * its top face, frames of one 1 ms substep without gravity. Times (wall, median over the frames):
 *   first   the first frame: the map's first build and the step;
 *   steady  a frame with the map kept;
 *   update  sph_sdf_update of the distances (the copy in);
 *   rebuilt a frame after such an update: the map again and the step.
 * "map" is rebuilt - steady: the map's build, on the host threads (CPU) or the device (CUDA).
 * What changes (--change):
 *   whole   the whole channel, every voxel's value: the box's half side grows by a tenth of a voxel
 *           and shrinks back on alternate frames (a deforming collider: every voxel changes);
 *   dent    a ball of radius --dent (m) carved into the top face, at a new place each frame, and
 *           only its box of voxels sent (a terrain dug in one place; the CPU recomputes only the
 *           voxels within reach of those that changed from the asset's second change on).
 * Before the timed frames one untimed update ("first change"): on the CPU an asset's first change
 * recomputes the whole map whatever changed (the map keeps the distances it was made from only
 * once its asset has changed).
 *
 *   boundary_map_rebuild [--backend cpu|cuda|auto] [--half 0.25] [--voxel 0.01] [--frames 5]
 *                        [--spacing 0.02] [--change whole|dent] [--dent 0.03]
 *
 * Uses only the public C API and tests/support's context and lattice helpers.
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sph_c.h"
#include "support.h"

#define MAX_FRAMES 64

static double now_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

static double median(double* values, int count) {
  qsort(values, (size_t)count, sizeof(double), compare_doubles);
  return count % 2 ? values[count / 2] : 0.5 * (values[count / 2 - 1] + values[count / 2]);
}

static int check(sph_result r, const char* what) {
  if (r == SPH_OK) return 1;
  fprintf(stderr, "boundary_map_rebuild: %s: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
  return 0;
}

/* The distance of a box of half side `half` centred at the origin. */
static float box_distance(double x, double y, double z, double half) {
  const double q[3] = {fabs(x) - half, fabs(y) - half, fabs(z) - half};
  const double outside = sqrt(fmax(q[0], 0.0) * fmax(q[0], 0.0) + fmax(q[1], 0.0) * fmax(q[1], 0.0) +
                              fmax(q[2], 0.0) * fmax(q[2], 0.0));
  const double inside = fmin(fmax(q[0], fmax(q[1], q[2])), 0.0);
  return (float)(outside + inside);
}

#define MAX_DENTS (MAX_FRAMES + 1)

/* What frame f's update sends: the box of half side `half` (a tenth of a voxel more on even frames
 * for "whole"), less, for "dent", the balls of radius `dent` carved into its top face by frames
 * 0..f, over the voxel box [lo, lo + size) of the grid `dims` (centred on the origin). */
typedef struct {
  int dents; /* 0: "whole" */
  double radius, centre[MAX_DENTS][3];
} change_plan;

static void fill(float* out, const uint32_t dims[3], const uint32_t lo[3], const uint32_t size[3],
                 double voxel, double half, const change_plan* plan) {
  for (uint32_t k = 0; k < size[2]; ++k)
    for (uint32_t j = 0; j < size[1]; ++j)
      for (uint32_t i = 0; i < size[0]; ++i) {
        const double p[3] = {((double)(lo[0] + i) - 0.5 * (dims[0] - 1)) * voxel,
                             ((double)(lo[1] + j) - 0.5 * (dims[1] - 1)) * voxel,
                             ((double)(lo[2] + k) - 0.5 * (dims[2] - 1)) * voxel};
        double d = box_distance(p[0], p[1], p[2], half);
        for (int b = 0; b < plan->dents; ++b) {
          const double* c = plan->centre[b];
          const double r = sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                (p[2] - c[2]) * (p[2] - c[2]));
          d = fmax(d, plan->radius - r);
        }
        out[i + (size_t)size[0] * (j + (size_t)size[1] * k)] = (float)d;
      }
}

int main(int argc, char** argv) {
  sph_backend backend = SPH_BACKEND_CPU;
  double half = 0.25, voxel = 0.01, spacing = 0.02, dent = 0.03;
  int frames = 5, dents = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--backend") == 0 && i + 1 < argc) {
      backend = support_backend_from_name(argv[++i], (sph_backend)-1);
      if ((int)backend < 0) {
        fprintf(stderr, "boundary_map_rebuild: --backend takes cpu, cuda or auto\n");
        return 2;
      }
    } else if (strcmp(argv[i], "--half") == 0 && i + 1 < argc) {
      half = atof(argv[++i]);
    } else if (strcmp(argv[i], "--voxel") == 0 && i + 1 < argc) {
      voxel = atof(argv[++i]);
    } else if (strcmp(argv[i], "--spacing") == 0 && i + 1 < argc) {
      spacing = atof(argv[++i]);
    } else if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = atoi(argv[++i]);
    } else if (strcmp(argv[i], "--change") == 0 && i + 1 < argc) {
      ++i;
      if (strcmp(argv[i], "whole") != 0 && strcmp(argv[i], "dent") != 0) {
        fprintf(stderr, "boundary_map_rebuild: --change takes whole or dent\n");
        return 2;
      }
      dents = strcmp(argv[i], "dent") == 0;
    } else if (strcmp(argv[i], "--dent") == 0 && i + 1 < argc) {
      dent = atof(argv[++i]);
    } else {
      fprintf(
          stderr,
          "usage: boundary_map_rebuild [--backend cpu|cuda|auto] [--half 0.25] [--voxel 0.01] [--frames 5] "
          "[--spacing 0.02] [--change whole|dent] [--dent 0.03]\n");
      return 2;
    }
  }
  if (!(half > 0.0) || !(voxel > 0.0) || !(spacing > 0.0) || !(dent > 0.0 && dent < half) || frames < 1 ||
      frames > MAX_FRAMES) {
    fprintf(
        stderr,
        "boundary_map_rebuild: --half, --voxel and --spacing must be > 0, --dent in (0, --half), --frames in "
        "[1, %d]\n",
        MAX_FRAMES);
    return 2;
  }

  sph_context* context = NULL;
  if (!check(support_context_create(backend, &context), "support_context_create")) return 1;
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 4096;
  def.particle_spacing = (float)spacing;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY;
  sph_world* world = NULL;
  sph_sdf* sdf = NULL;
  float* positions = NULL;
  float* distances = NULL;
  int ok = check(sph_world_create(context, &def, &world), "sph_world_create");
  if (ok) ok = check(support_set_gravity_and_steps(world, 0.0f, 0.0f, 0.0f, 1e-4f, 1e-3f), "set params");
  sph_shape_desc shape;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = (float)half;
  shape.voxel_size = (float)voxel;
  if (ok) ok = check(sph_sdf_create_shape(context, &shape, &sdf), "sph_sdf_create_shape");
  sph_collider_def collider;
  sph_collider_def_init(&collider);
  collider.sdf = sdf;
  sph_collider_id id;
  if (ok) ok = check(sph_collider_create(world, &collider, &id), "sph_collider_create");
  /* A block of 8 x 2 x 8 lattice steps resting on the top face (its lowest layer half a step up). */
  const uint32_t layers[3] = {8, 2, 8};
  const double step = spacing / sqrt(2.0);
  const double origin[3] = {-4.0 * step, half, -4.0 * step};
  uint32_t count = 0;
  if (ok) ok = check(support_fcc_box(layers, step, origin, &positions, &count), "support_fcc_box");
  if (ok) ok = check(support_spawn(world, positions, NULL, count), "support_spawn");
  uint32_t dims[3] = {0, 0, 0};
  if (ok) ok = check(sph_sdf_get_dims(sdf, dims), "sph_sdf_get_dims");
  const size_t voxels = (size_t)dims[0] * dims[1] * dims[2];
  if (ok) {
    distances = (float*)malloc(voxels * sizeof(float));
    ok = distances != NULL;
    if (!ok) fprintf(stderr, "boundary_map_rebuild: out of host memory for %zu voxels\n", voxels);
  }
  double first = 0.0, steady[MAX_FRAMES], update[MAX_FRAMES], rebuilt[MAX_FRAMES];
  if (ok) {
    const double t0 = now_seconds();
    ok = check(sph_world_step(world, 1e-3f), "sph_world_step (first)");
    first = now_seconds() - t0;
  }
  for (int f = 0; ok && f < frames; ++f) {
    const double t0 = now_seconds();
    ok = check(sph_world_step(world, 1e-3f), "sph_world_step (steady)");
    steady[f] = now_seconds() - t0;
  }
  /* Frame 0 is the asset's first change (timed apart), frames 1..frames the timed ones. */
  change_plan plan;
  memset(&plan, 0, sizeof plan);
  plan.radius = dent;
  double first_change = 0.0;
  for (int f = 0; ok && f <= frames; ++f) {
    uint32_t lo[3] = {0, 0, 0}, size[3] = {dims[0], dims[1], dims[2]};
    if (dents) {
      /* Along x on the top face, each ball 2.5 radii from the last, wrapping within the face. */
      double* c = plan.centre[plan.dents++];
      c[0] = -0.8 * half + fmod(2.5 * dent * f, 1.6 * half), c[1] = half, c[2] = 0.0;
      for (int a = 0; a < 3; ++a) {
        const double from = (c[a] - dent) / voxel + 0.5 * (dims[a] - 1) - 1.0;
        const double to = (c[a] + dent) / voxel + 0.5 * (dims[a] - 1) + 2.0;
        lo[a] = from < 0.0 ? 0u : (uint32_t)from;
        const uint32_t hi = to > dims[a] ? dims[a] : (uint32_t)to;
        size[a] = hi - lo[a];
      }
    }
    const change_plan whole = {0, 0.0, {{0.0}}};
    fill(distances, dims, lo, size, (double)(float)voxel, half + (!dents && f % 2 == 0 ? 0.1 * voxel : 0.0),
         dents ? &plan : &whole);
    const double t0 = now_seconds();
    ok = check(sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, lo, size, distances, SPH_MEMORY_HOST),
               "sph_sdf_update");
    const double t1 = now_seconds();
    if (ok) ok = check(sph_world_step(world, 1e-3f), "sph_world_step (rebuilt)");
    if (f == 0) {
      first_change = now_seconds() - t0;
      continue;
    }
    update[f - 1] = t1 - t0;
    rebuilt[f - 1] = now_seconds() - t1;
  }
  if (ok) {
    const double s = median(steady, frames), u = median(update, frames), r = median(rebuilt, frames);
    printf(
        "backend %s, box half side %.4g m, voxel %.4g m: %u x %u x %u = %zu voxels; %u particles, h %.4g m\n",
        backend == SPH_BACKEND_CUDA ? "cuda" : (backend == SPH_BACKEND_CPU ? "cpu" : "auto"), half, voxel,
        dims[0], dims[1], dims[2], voxels, count, 1.8 * spacing);
    if (dents)
      printf("change: a dent of radius %.4g m a frame; ", dent);
    else
      printf("change: every voxel a frame; ");
    printf("first change (update and step) %.2f ms\n", 1e3 * first_change);
    printf(
        "first %.2f ms, steady %.3f ms, update %.2f ms, rebuilt %.2f ms (medians of %d frames); map %.2f "
        "ms\n",
        1e3 * first, 1e3 * s, 1e3 * u, 1e3 * r, frames, 1e3 * (r - s));
  }
  free(distances);
  free(positions);
  if (sdf) sph_sdf_destroy(sdf);
  if (world) sph_world_destroy(world);
  sph_context_destroy(context);
  return ok ? 0 : 1;
}
