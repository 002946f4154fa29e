// SPDX-License-Identifier: MIT
#include "extremes_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ext_ok(sph_result r, const char* call, const char* file, int line) {
  if (r < 0) {
    print_error("%s -> %s: %s\n", call, sph_result_string(r), sph_get_last_error());
    _fail(file, line);
  }
}

void ext_open_def(ext_world* w, sph_world_def def) {
  EXT_OK(support_world_open(w, sph_test_backend(), &def, NULL));
}

void ext_open(ext_world* w, uint32_t capacity, float spacing) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.particle_spacing = spacing;
  ext_open_def(w, def);
}

void ext_close(ext_world* w) { EXT_OK(support_world_close(w)); }

void ext_set_params(ext_world* w) { EXT_OK(support_world_set_params(w)); }

void ext_spawn(ext_world* w, const float* positions, const float* velocities, uint32_t count) {
  EXT_OK(support_spawn(w->world, positions, velocities, count));
}

void* ext_copy(const sph_world* world, sph_attribute attribute, uint32_t* out_count) {
  void* buffer = NULL;
  EXT_OK(support_copy(world, attribute, &buffer, out_count));
  return buffer;
}

double ext_mechanical_energy(const sph_world* world, float mass, float g) {
  uint32_t n = 0, i;
  float* x = (float*)ext_copy(world, SPH_ATTRIBUTE_POSITION, &n);
  float* v = (float*)ext_copy(world, SPH_ATTRIBUTE_VELOCITY, &n);
  double e = 0.0;
  for (i = 0; i < n; ++i) {
    const double v2 = (double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
                      (double)v[3 * i + 2] * v[3 * i + 2];
    e += 0.5 * mass * v2 + (double)mass * g * x[3 * i + 1];
  }
  free(x);
  free(v);
  return e;
}

void ext_tank_build(ext_world* w, ext_tank* t) {
  support_tank tank;
  sph_vec3 column_min, column_max;
  uint32_t added = 0;
  tank.centre.x = 0.0f;
  tank.centre.y = t->hy;
  tank.centre.z = 0.0f;
  tank.half_extents.x = t->hx;
  tank.half_extents.y = t->hy;
  tank.half_extents.z = t->hz;
  tank.voxel_size = 0.01f;
  tank.friction = 0.0f;
  column_min.x = -t->hx;
  column_min.y = 0.0f;
  column_min.z = -t->hz;
  column_max.x = -t->hx + t->column_width;
  column_max.y = t->column_height;
  column_max.z = t->hz;
  EXT_OK(
      support_dam_break(w->context, w->world, &tank, column_min, column_max, &t->sdf, &t->collider, &added));
  assert_true(added > 0);
}

void ext_tank_destroy(ext_world* w, ext_tank* t) {
  EXT_OK(sph_collider_destroy(w->world, t->collider));
  EXT_OK(sph_sdf_destroy(t->sdf));
}

static int finite3(const float* p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

ext_measure ext_tank_run(ext_world* w, const ext_tank* t, int frames, float frame_dt) {
  ext_measure m;
  uint32_t n = 0, i;
  float* x = (float*)ext_copy(w->world, SPH_ATTRIBUTE_POSITION, &n);
  const double e0 = ext_mechanical_energy(w->world, w->mass, EXT_G);
  int frame;
  memset(&m, 0, sizeof m);
  m.finite = 1;
  m.worst_depth = -1.0f;
  for (i = 0; i < n; ++i) m.drop_energy += w->mass * EXT_G * x[3 * i + 1];
  free(x);
  for (frame = 0; frame < frames; ++frame) {
    sph_stats st;
    float *v, *rho;
    double e;
    EXT_OK(sph_world_step(w->world, frame_dt));
    sph_stats_init(&st);
    EXT_OK(sph_world_get_stats(w->world, &st));
    m.substeps += st.substeps;
    if (st.dt_max > m.largest_dt) m.largest_dt = st.dt_max;
    x = (float*)ext_copy(w->world, SPH_ATTRIBUTE_POSITION, &m.count);
    v = (float*)ext_copy(w->world, SPH_ATTRIBUTE_VELOCITY, &m.count);
    rho = (float*)ext_copy(w->world, SPH_ATTRIBUTE_DENSITY, &m.count);
    for (i = 0; i < m.count; ++i) {
      const float* p = x + 3 * i;
      const float* u = v + 3 * i;
      const float speed = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      const float depth = fmaxf(fmaxf(fabsf(p[0]) - t->hx, fabsf(p[1] - t->hy) - t->hy), fabsf(p[2]) - t->hz);
      if (!finite3(p) || !finite3(u) || !isfinite(rho[i])) m.finite = 0;
      if (speed > m.max_speed) m.max_speed = speed;
      if (rho[i] > m.density_max) m.density_max = rho[i];
      if (depth > m.worst_depth) m.worst_depth = depth;
    }
    free(x);
    free(v);
    free(rho);
    e = ext_mechanical_energy(w->world, w->mass, EXT_G);
    if ((float)(e - e0) > m.max_energy_gain) m.max_energy_gain = (float)(e - e0);
  }
  return m;
}
