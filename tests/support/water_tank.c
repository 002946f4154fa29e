// SPDX-License-Identifier: MIT
/* Water at rest in a closed tank: a lattice tiling a box (support_fcc_box) spawned in a tank
 * (support_tank_between), and the two such scenes several tests share. */
#include <stdlib.h>

#include "support.h"

sph_result support_water_tank_open(support_world* w, sph_backend backend, const sph_world_def* def,
                                   const sph_world_params* params, const support_water_tank* scene,
                                   sph_sdf** sdf, sph_collider_id* collider, uint32_t* count) {
  sph_world_def d;
  float* lattice = NULL;
  uint32_t n = 0;
  sph_result r;
  /* Measurement only (docs/validation.md, "The resting tank's probes against the weight above"):
   * WATER_TANK_NUDGE (m; default 0) moves the lattice by that much along each axis, a draw of the
   * same settling; WATER_TANK_VOXEL (lattice steps; default 0.5) is the tank's SDF voxel. */
  const double nudge = getenv("WATER_TANK_NUDGE") ? atof(getenv("WATER_TANK_NUDGE")) : 0.0;
  const double origin[3] = {nudge, nudge, nudge};
  const double voxel = getenv("WATER_TANK_VOXEL") ? atof(getenv("WATER_TANK_VOXEL")) : 0.5;
  if (sdf) *sdf = NULL;
  if ((r = sph_world_def_init(&d)) != SPH_OK) return r;
  if (def) d = *def;
  r = support_fcc_box(scene->layers, scene->step, nudge != 0.0 ? origin : NULL, &lattice, &n);
  if (r == SPH_OK) {
    if (d.capacity == 0) d.capacity = n;
    r = support_world_open(w, backend, &d, params);
  }
  if (r == SPH_OK)
    r = support_tank_between(w->context, w->world, scene->tank_min, scene->tank_max, voxel * scene->step,
                             scene->friction, sdf, collider);
  if (r == SPH_OK) r = support_spawn(w->world, lattice, NULL, n);
  if (r == SPH_OK && count) *count = n;
  free(lattice);
  return r;
}

support_water_tank support_collapsing_column(float friction) {
  const support_water_tank scene = {{6, 14, 8}, 0.01, {0.0, 0.0, 0.0}, {0.16, 0.30, 0.08}, 0.0f};
  support_water_tank out = scene;
  out.friction = friction;
  return out;
}

support_water_tank support_resting_tank(void) {
  const support_water_tank scene = {{12, 24, 12}, 0.01, {0.0, 0.0, 0.0}, {0.12, 2.0 * 0.24, 0.12}, 0.0f};
  return scene;
}
