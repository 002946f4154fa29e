/* SPDX-License-Identifier: MIT */
/* Collider loads and probes in a distributed world (docs/distributed.md) against one undivided
 * world, under mpirun on 1-4 ranks: the stirred column in its tank with SPH_FEATURE_COLLIDER_LOADS,
 * a point probe inside the column and a gauge along y (the slabs' axis: its points lie in every
 * rank's slab), sampled every substep; 16 substeps in frames of 8. Checked:
 *   - every rank reads the same loads and the same readings, bit for bit (the loads are added over
 *     the ranks in rank order; each probe point is gathered by its slab's rank);
 *   - the probes' readings are the undivided world's bit for bit: a point's neighbour cells are
 *     complete on its slab's rank and list their particles in the undivided world's order;
 *   - the loads are the undivided world's within 1e-6 of the force's (and the torque's)
 *     magnitude: each rank sums its own particles' impulses in blocks of storage order (float
 *     blocks, then doubles), so the blocks hold other particles than the undivided world's and
 *     round differently; measured ~1e-8 relative (the float block sums' rounding, 6e-8 relative
 *     each, over a few hundred impulses of one sign);
 *   - thresholds (a tenth of the first frame's load and peak pressure): each rank reports the
 *     undivided world's load and pressure events in the second frame;
 *   - the particles are the undivided world's bit for bit (the loads read the contacts, they do
 *     not change them). */
#include "mpi_compare.h"

typedef struct readings {
  sph_collider_loads loads;
  sph_probe_reading point, gauge;
  uint32_t load_events, pressure_events;
} readings;

static void read_world(sph_world* w, sph_collider_id tank, sph_probe_id point, sph_probe_id gauge,
                       readings* r) {
  sph_event events[16];
  uint32_t count = 0;
  memset(r, 0, sizeof *r);
  REQUIRE(sph_collider_loads_init(&r->loads) == SPH_OK, "loads init");
  REQUIRE(sph_probe_reading_init(&r->point) == SPH_OK && sph_probe_reading_init(&r->gauge) == SPH_OK,
          "reading init");
  REQUIRE(sph_collider_get_loads(w, tank, &r->loads) == SPH_OK, "loads");
  REQUIRE(sph_probe_get_reading(w, point, &r->point) == SPH_OK, "point");
  REQUIRE(sph_probe_get_reading(w, gauge, &r->gauge) == SPH_OK, "gauge");
  REQUIRE(sph_world_get_events(w, events, 16, &count) == SPH_OK, "events");
  for (uint32_t i = 0; i < count; ++i) {
    if (events[i].type == SPH_EVENT_COLLIDER_LOAD_EXCEEDED) ++r->load_events;
    if (events[i].type == SPH_EVENT_PROBE_PRESSURE_EXCEEDED) ++r->pressure_events;
  }
}

static double norm3(const sph_vec3* v) {
  return sqrt((double)v->x * v->x + (double)v->y * v->y + (double)v->z * v->z);
}

static double distance3(const sph_vec3* a, const sph_vec3* b) {
  const sph_vec3 d = {a->x - b->x, a->y - b->y, a->z - b->z};
  return norm3(&d);
}

int main(int argc, char** argv) {
  const sph_vec3 column_min = {0.0f, 0.0f, 0.0f}, column_max = {0.1f, 0.2f, 0.06f};
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* single = NULL;
  sph_world* world = NULL;
  sph_collider_id single_tank = {0}, tank = {0};
  sph_probe_id point, gauge, single_point = {0}, single_gauge = {0};
  float thresholds[2] = {0.0f, 0.0f};
  mpi_test_init(&argc, &argv, &context);
  mpi_test_world_def(&def);
  def.features = SPH_FEATURE_COLLIDER_LOADS;
  (void)make_worlds(context, &def, column_min, column_max, 2.0f, &single, &world, &single_tank, &tank);
  mpi_test_add_probes(world, &point, &gauge);
  if (single) mpi_test_add_probes(single, &single_point, &single_gauge);
  for (int f = 0; f < 2; ++f) {
    readings got, want;
    sph_stats stats;
    mpi_test_step_stats(world, 8, 1, &stats);
    read_world(world, tank, point, gauge, &got);
    CHECK(same_on_every_rank(&got, (int)sizeof got),
          "frame %d: the ranks read different loads, readings or events", f);
    if (g_rank == 0) {
      mpi_test_step_stats(single, 8, 0, &stats);
      read_world(single, single_tank, single_point, single_gauge, &want);
      CHECK(memcmp(&got.point, &want.point, sizeof got.point) == 0 &&
                memcmp(&got.gauge, &want.gauge, sizeof got.gauge) == 0,
            "frame %d on %d ranks: probe readings differ: point %.9g Pa %.9g kg/m3, gauge %.9g m; the "
            "undivided "
            "world %.9g Pa %.9g kg/m3, %.9g m",
            f, g_size, (double)got.point.pressure, (double)got.point.density, (double)got.gauge.water_height,
            (double)want.point.pressure, (double)want.point.density, (double)want.gauge.water_height);
      {
        const double df = distance3(&got.loads.force, &want.loads.force) / norm3(&want.loads.force);
        const double dt = distance3(&got.loads.torque, &want.loads.torque) / norm3(&want.loads.torque);
        CHECK(norm3(&want.loads.force) > 0.0 && df <= 1e-6 && dt <= 1e-6,
              "frame %d on %d ranks: loads %g N / %g N m off by %.3g / %.3g relative", f, g_size,
              norm3(&want.loads.force), norm3(&want.loads.torque), df, dt);
        CHECK(got.load_events == want.load_events && got.pressure_events == want.pressure_events,
              "frame %d: %u load and %u pressure events; the undivided world %u and %u", f, got.load_events,
              got.pressure_events, want.load_events, want.pressure_events);
        CHECK(f == 0 || (want.load_events == 1 && want.pressure_events == 1),
              "frame %d: the thresholds at a tenth of the first frame's values raised %u and %u events", f,
              want.load_events, want.pressure_events);
        printf(
            "frame %d on %d ranks: load %.9g N (%.3g relative off), torque %.9g N m (%.3g), gauge %.9g m, "
            "point %.9g Pa\n",
            f, g_size, norm3(&got.loads.force), df, norm3(&got.loads.torque), dt,
            (double)got.gauge.water_height, (double)got.point.pressure);
        thresholds[0] = 0.1f * (float)norm3(&want.loads.force);
        thresholds[1] = 0.1f * want.point.pressure_max;
      }
    }
    if (f == 0) {
      /* Thresholds at a tenth of the first frame's values: the second frame raises both events. */
      MPI_Bcast(thresholds, 2, MPI_FLOAT, 0, MPI_COMM_WORLD);
      REQUIRE(sph_collider_set_load_threshold(world, tank, thresholds[0]) == SPH_OK, "load threshold");
      REQUIRE(sph_probe_set_pressure_threshold(world, point, thresholds[1]) == SPH_OK, "pressure threshold");
      if (single) {
        REQUIRE(sph_collider_set_load_threshold(single, single_tank, thresholds[0]) == SPH_OK,
                "load threshold");
        REQUIRE(sph_probe_set_pressure_threshold(single, single_point, thresholds[1]) == SPH_OK,
                "pressure threshold");
      }
    }
  }
  expect_same_particles(single, world, "loads and probes");
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (single) REQUIRE(sph_world_destroy(single) == SPH_OK, "destroy");
  return mpi_test_finish(context, "mpi_scene_sums");
}
