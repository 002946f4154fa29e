// SPDX-License-Identifier: MIT
/* The hydrostatic tank's second pressure reading: the library's probes (docs/physics.md "Probes and
 * gauges"), the Shepard-normalised SPH interpolant of the particles' pressure with W_poly6, read
 * along horizontal gauge lines. Per slice of the particle reading's bins, lines at the slice's
 * mid-height run along x over the interior (h from the side walls), one every lattice step in z;
 * each line's pressure is the interpolant's mean over its samples, sampled every substep. This is
 * the pressure a user reads through the C API, at exactly known heights (no particle's height
 * enters), and it smooths the particles' pressure over one kernel radius in every direction. */
#include "hydrostatic_tank_gauges.h"

#include <stdlib.h>

#include "validation_util.h"

struct tank_gauges {
  uint32_t bins, lines_per_bin;
  sph_probe_id* ids;  /* bins x lines_per_bin; a bin above the water has none */
  uint32_t* in_water; /* per bin: 1 when its lines were made */
  double* pressure;   /* per bin: the sum of its lines' readings over the frames read */
  uint32_t* readings; /* per bin */
};

tank_gauges* tank_gauges_create(sph_world* world, double width, double depth, double h, double bin,
                                uint32_t bins, double step) {
  tank_gauges* g = (tank_gauges*)calloc(1, sizeof(tank_gauges));
  assert_non_null(g);
  g->bins = bins;
  g->lines_per_bin = (uint32_t)((width - 2.0 * h) / step) + 1u;
  g->ids = (sph_probe_id*)calloc((size_t)bins * g->lines_per_bin, sizeof(sph_probe_id));
  g->in_water = (uint32_t*)calloc(bins, sizeof(uint32_t));
  g->pressure = (double*)calloc(bins, sizeof(double));
  g->readings = (uint32_t*)calloc(bins, sizeof(uint32_t));
  assert_true(g->ids && g->in_water && g->pressure && g->readings);
  for (uint32_t b = 0; b < bins; ++b) {
    const double y = (b + 0.5) * bin;
    if (y > depth) continue;
    g->in_water[b] = 1u;
    for (uint32_t l = 0; l < g->lines_per_bin; ++l) {
      sph_probe_def def;
      EXPECT_OK(sph_probe_def_init(&def));
      def.kind = SPH_PROBE_GAUGE;
      def.sampling = SPH_PROBE_EVERY_SUBSTEP;
      def.position.x = (float)h;
      def.position.y = (float)y;
      def.position.z = (float)(h + l * step);
      def.direction.x = 1.0f;
      def.length = (float)(width - 2.0 * h);
      EXPECT_OK(sph_probe_create(world, &def, &g->ids[(size_t)b * g->lines_per_bin + l]));
    }
  }
  return g;
}

void tank_gauges_read(tank_gauges* g, const sph_world* world) {
  for (uint32_t b = 0; b < g->bins; ++b) {
    if (!g->in_water[b]) continue;
    for (uint32_t l = 0; l < g->lines_per_bin; ++l) {
      sph_probe_reading r;
      EXPECT_OK(sph_probe_reading_init(&r));
      EXPECT_OK(sph_probe_get_reading(world, g->ids[(size_t)b * g->lines_per_bin + l], &r));
      g->pressure[b] += r.pressure;
      ++g->readings[b];
    }
  }
}

void tank_gauges_profile(const tank_gauges* g, double bin, double* pressure, double* y, uint32_t* count) {
  for (uint32_t b = 0; b < g->bins; ++b) {
    count[b] = g->readings[b];
    pressure[b] = g->readings[b] ? g->pressure[b] / g->readings[b] : 0.0;
    y[b] = (b + 0.5) * bin;
  }
}

void tank_gauges_destroy(tank_gauges* g, sph_world* world) {
  if (!g) return;
  for (size_t i = 0; i < (size_t)g->bins * g->lines_per_bin; ++i)
    if (g->ids[i].bits) EXPECT_OK(sph_probe_destroy(world, g->ids[i]));
  free(g->ids);
  free(g->in_water);
  free(g->pressure);
  free(g->readings);
  free(g);
}
