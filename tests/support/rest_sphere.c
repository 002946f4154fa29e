// SPDX-License-Identifier: MIT
/* The rest sphere: an FCC ball at rest density in a world of its own, with random velocities. */
#include <stdlib.h>

#include "support.h"

sph_result support_rest_sphere_open(support_world* w, sph_backend backend, const sph_world_def* def,
                                    const sph_world_params* params, support_sphere* sphere, uint32_t* count) {
  sph_world_def d;
  float* positions = NULL;
  float* velocities = NULL;
  double spacing;
  uint32_t n = 0;
  sph_result r;
  if ((r = sph_world_def_init(&d)) != SPH_OK) return r;
  spacing = d.particle_spacing; /* the default, for a def that leaves it 0 */
  if (def) d = *def;
  if (d.particle_spacing > 0.0f) spacing = d.particle_spacing;
  if (sphere->spacing > 0.0) spacing = sphere->spacing;
  r = support_fcc_sphere(sphere->centre, sphere->radius, spacing, &positions, &n);
  if (r == SPH_OK) {
    velocities = (float*)malloc(sizeof(float) * 3 * ((size_t)n + 1));
    if (velocities == NULL) r = SPH_ERROR_OUT_OF_HOST_MEMORY;
  }
  if (r == SPH_OK) {
    support_random_velocities(velocities, n, sphere->speed, sphere->drift, &sphere->random_state);
    if (d.capacity == 0) d.capacity = n + sphere->spare_capacity;
    r = support_world_open(w, backend, &d, params);
  }
  if (r == SPH_OK) r = support_spawn(w->world, positions, velocities, n);
  if (r == SPH_OK && count) *count = n;
  free(positions);
  free(velocities);
  return r;
}
