// SPDX-License-Identifier: MIT
#include "capi_scenes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double kGravity = 9.81;

capi_momentum_balance capi_collapse_momentum_balance(const sph_world_def* def, uint32_t dfsph_flags,
                                                     uint32_t dfsph_linear_solver) {
  const support_water_tank column = support_collapsing_column(0.0f);
  support_world w;
  sph_sdf* sdf = NULL;
  sph_collider_id tank;
  capi_momentum_balance out;
  double p0[3], p1[3];
  memset(&out, 0, sizeof out);
  EXPECT_OK(support_water_tank_open(&w, sph_test_backend(), def, NULL, &column, &sdf, &tank, &out.count));
  if (dfsph_flags) capi_set_dfsph_flags(w.world, dfsph_flags);
  if (dfsph_linear_solver) {
    sph_dfsph_params dp;
    EXPECT_OK(sph_dfsph_params_init(&dp));
    EXPECT_OK(sph_world_get_dfsph_params(w.world, &dp));
    dp.linear_solver = dfsph_linear_solver;
    EXPECT_OK(sph_world_set_dfsph_params(w.world, &dp));
  }
  capi_fluid_momentum(w.world, w.mass, p0);
  for (int frame = 0; frame < 15; ++frame) {
    sph_collider_loads l;
    EXPECT_OK(sph_world_step(w.world, 0.02f));
    l = capi_loads_of(w.world, tank);
    out.impulse[0] += l.force.x * l.frame_time;
    out.impulse[1] += l.force.y * l.frame_time;
    out.impulse[2] += l.force.z * l.frame_time;
    out.time += l.frame_time;
  }
  capi_fluid_momentum(w.world, w.mass, p1);
  for (int k = 0; k < 3; ++k) out.fluid_change[k] = p1[k] - p0[k];
  out.weight_impulse = (double)out.count * w.mass * -kGravity * out.time;
  {
    const double residual[3] = {out.fluid_change[0] + out.impulse[0],
                                out.fluid_change[1] + out.impulse[1] - out.weight_impulse,
                                out.fluid_change[2] + out.impulse[2]};
    out.error = sqrt(residual[0] * residual[0] + residual[1] * residual[1] + residual[2] * residual[2]) /
                fabs(out.weight_impulse);
  }
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&w));
  return out;
}

void capi_submerged_box_open(capi_submerged_box* s, const sph_world_def* def,
                             const sph_world_params* params) {
  const uint32_t layers[3] = {16, 20, 16};
  const double step = 0.01, side = 0.16, half = CAPI_SUBMERGED_HALF, centre[3] = {0.08, 0.08, 0.08};
  const double tank_min[3] = {0.0, 0.0, 0.0}, tank_max[3] = {side, 0.4, side};
  float* lattice = NULL;
  uint32_t n = 0;
  sph_world_def d = *def;
  sph_shape_desc shape;
  sph_collider_def collider;
  memset(s, 0, sizeof *s);
  assert_int_equal(support_fcc_box(layers, step, NULL, &lattice, &n), SPH_OK);
  for (uint32_t i = 0; i < n; ++i) {
    int inside = 1;
    /* The cut lies a quarter step beyond the faces: the first layer outside lies half a step from
     * each face, exactly at half + step / 2, where a cut there dropped it by float rounding below
     * the bottom, -x and -z faces (and kept it above the others) until session 17. */
    for (int k = 0; k < 3; ++k) inside = inside && fabs(lattice[3 * i + k] - centre[k]) < half + 0.25 * step;
    if (inside) continue;
    memmove(lattice + 3 * s->count, lattice + 3 * i, 3 * sizeof(float));
    ++s->count;
  }
  if (d.capacity == 0) d.capacity = s->count;
  EXPECT_OK(support_world_open(&s->w, sph_test_backend(), &d, params));
  EXPECT_OK(support_tank_between(s->w.context, s->w.world, tank_min, tank_max, 0.5 * step, 0.0f, &s->tank_sdf,
                                 NULL));
  EXPECT_OK(sph_shape_desc_init(&shape));
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = (float)half;
  shape.voxel_size = 0.005f;
  shape.padding_voxels = 8; /* the grid reaches beyond the kernel radius plus the walls' offset */
  EXPECT_OK(sph_sdf_create_shape(s->w.context, &shape, &s->box_sdf));
  EXPECT_OK(sph_collider_def_init(&collider));
  collider.sdf = s->box_sdf;
  collider.transform = sph_transform_identity();
  collider.transform.position.x = (float)centre[0];
  collider.transform.position.y = (float)centre[1];
  collider.transform.position.z = (float)centre[2];
  EXPECT_OK(sph_collider_create(s->w.world, &collider, &s->box));
  EXPECT_OK(support_spawn(s->w.world, lattice, NULL, s->count));
  free(lattice);
}

void capi_submerged_box_close(capi_submerged_box* s) {
  EXPECT_OK(sph_sdf_destroy(s->tank_sdf));
  EXPECT_OK(sph_sdf_destroy(s->box_sdf));
  EXPECT_OK(support_world_close(&s->w));
}

void capi_mean_force(sph_world* world, sph_collider_id collider, int frames, int first_averaged,
                     double force[3]) {
  double sum[3] = {0.0, 0.0, 0.0}, time = 0.0;
  for (int frame = 0; frame < frames; ++frame) {
    EXPECT_OK(sph_world_step(world, 0.02f));
    if (frame < first_averaged) continue;
    {
      const sph_collider_loads l = capi_loads_of(world, collider);
      sum[0] += l.force.x * l.frame_time;
      sum[1] += l.force.y * l.frame_time;
      sum[2] += l.force.z * l.frame_time;
      time += l.frame_time;
    }
  }
  for (int k = 0; k < 3; ++k) force[k] = sum[k] / time;
}

const double capi_resting_heights[CAPI_RESTING_PROBES] = {0.04, 0.08, 0.12, 0.16};

static sph_probe_id add_probe(sph_world* world, sph_probe_kind kind, double y, double length,
                              sph_probe_sampling sampling) {
  sph_probe_def def;
  sph_probe_id id = {0};
  EXPECT_OK(sph_probe_def_init(&def));
  def.kind = kind;
  def.sampling = sampling;
  def.position.x = def.position.z = (float)(CAPI_RESTING_WIDTH / 2);
  def.position.y = (float)y;
  def.length = (float)length;
  EXPECT_OK(sph_probe_create(world, &def, &id));
  return id;
}

void capi_resting_tank_open(capi_resting_tank* t, const sph_world_def* def, const sph_world_params* params,
                            sph_probe_sampling gauge_sampling) {
  const support_water_tank water = support_resting_tank();
  memset(t, 0, sizeof *t);
  EXPECT_OK(
      support_water_tank_open(&t->w, sph_test_backend(), def, params, &water, &t->sdf, NULL, &t->count));
  for (int k = 0; k < CAPI_RESTING_PROBES; ++k)
    t->probes[k] =
        add_probe(t->w.world, SPH_PROBE_POINT, capi_resting_heights[k], 0.0, SPH_PROBE_EVERY_SUBSTEP);
  t->gauge = add_probe(t->w.world, SPH_PROBE_GAUGE, -0.03, 0.48, gauge_sampling);
}

void capi_resting_tank_close(capi_resting_tank* t) {
  EXPECT_OK(sph_sdf_destroy(t->sdf));
  EXPECT_OK(support_world_close(&t->w));
}

double capi_resting_water_area(void) {
  const double width = CAPI_RESTING_WIDTH - 2.0 * CAPI_RESTING_FILM;
  return width * width;
}

/* The share of a particle's mass above y: poly6, W = 315 / (64 pi h^9) (h^2 - r^2)^3, integrated
 * over the horizontal plane at height offset t h from its centre is (315 / 256) (1 - t^2)^4 / h
 * (normalised over t in [-1, 1]); its integral from t to 1 is 1/2 - (315 / 256) G(t),
 * G(t) = t - 4 t^3 / 3 + 6 t^5 / 5 - 4 t^7 / 7 + t^9 / 9 (G(1) = 128 / 315). */
static double kernel_share_above(double t) {
  const double u = fmin(1.0, fmax(-1.0, t)), u2 = u * u;
  const double g = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
  return 0.5 - 315.0 / 256.0 * g;
}

void capi_count_above(const sph_world* world, double h, const double* heights, int n, double* kernel,
                      double* slab) {
  const double step = 0.01; /* support_resting_tank's lattice step */
  uint32_t count = 0;
  float* x;
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  x = (float*)malloc(sizeof(float) * 3 * (count ? count : 1));
  assert_non_null(x);
  EXPECT_OK(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, x, sizeof(float) * 3 * count, 0, 0, count,
                                     NULL));
  for (uint32_t j = 0; j < count; ++j)
    for (int i = 0; i < n; ++i) {
      const double dy = x[3 * j + 1] - heights[i];
      if (kernel) kernel[i] += kernel_share_above(-dy / h);
      if (slab) slab[i] += fmin(1.0, fmax(0.0, dy / step + 0.5));
    }
  free(x);
}
