// SPDX-License-Identifier: MIT
/* A context and a world from a def and params, and particles spawned into it. */
#include <stdlib.h>
#include <string.h>

#include "support.h"

sph_result support_world_open(support_world* w, sph_backend backend, const sph_world_def* def,
                              const sph_world_params* params) {
  sph_world_def d;
  sph_result r;
  memset(w, 0, sizeof *w);
  if ((r = sph_world_def_init(&d)) != SPH_OK) return r;
  if (def) {
    const uint32_t struct_size = d.struct_size, header_version = d.header_version;
    d = *def;
    d.struct_size = struct_size;
    d.header_version = header_version;
  }
  if ((r = support_context_create(backend, &w->context)) != SPH_OK) return r;
  if ((r = sph_world_create(w->context, &d, &w->world)) != SPH_OK) return r;
  if (params && (r = sph_world_set_params(w->world, params)) != SPH_OK) return r;
  if ((r = sph_world_get_particle_mass(w->world, &w->mass)) != SPH_OK) return r;
  w->def = d;
  if ((r = sph_world_get_def(w->world, &w->def)) != SPH_OK) return r;
  if ((r = sph_world_params_init(&w->params)) != SPH_OK) return r;
  return sph_world_get_params(w->world, &w->params);
}

sph_result support_world_set_params(support_world* w) { return sph_world_set_params(w->world, &w->params); }

sph_result support_world_close(support_world* w) {
  sph_result r = SPH_OK;
  if (w->world) r = sph_world_destroy(w->world);
  if (r == SPH_OK && w->context) r = sph_context_destroy(w->context);
  memset(w, 0, sizeof *w);
  return r;
}

sph_result support_params_gravity_and_steps(sph_world_params* params, float gx, float gy, float gz,
                                            float dt_min, float dt_max) {
  const sph_result r = sph_world_params_init(params);
  if (r != SPH_OK) return r;
  params->gravity.x = gx;
  params->gravity.y = gy;
  params->gravity.z = gz;
  params->dt_min = dt_min;
  params->dt_max = dt_max;
  return SPH_OK;
}

sph_result support_set_gravity_and_steps(sph_world* world, float gx, float gy, float gz, float dt_min,
                                         float dt_max) {
  sph_world_params p;
  const sph_result r = support_params_gravity_and_steps(&p, gx, gy, gz, dt_min, dt_max);
  return r != SPH_OK ? r : sph_world_set_params(world, &p);
}

sph_result support_spawn(sph_world* world, const float* positions, const float* velocities, uint32_t count) {
  sph_spawn_desc spawn;
  const sph_result r = sph_spawn_desc_init(&spawn);
  if (r != SPH_OK) return r;
  spawn.count = count;
  spawn.positions = positions;
  spawn.velocities = velocities;
  return sph_world_spawn(world, &spawn, NULL);
}

sph_result support_spawn_disturbed(sph_world* world, const float* positions, uint32_t count, double speed,
                                   uint64_t* state, double* kinetic_energy) {
  float* velocities = (float*)malloc(sizeof(float) * 3 * ((size_t)count + 1));
  float mass = 0.0f;
  sph_result r;
  if (velocities == NULL) return SPH_ERROR_OUT_OF_HOST_MEMORY;
  support_random_velocities(velocities, count, speed, NULL, state);
  r = support_spawn(world, positions, velocities, count);
  if (r == SPH_OK && kinetic_energy) {
    double e = 0.0;
    r = sph_world_get_particle_mass(world, &mass);
    for (uint32_t i = 0; i < 3 * count; ++i) e += 0.5 * mass * (double)velocities[i] * velocities[i];
    *kinetic_energy = e;
  }
  free(velocities);
  return r;
}
