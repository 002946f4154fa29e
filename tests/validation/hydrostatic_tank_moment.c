// SPDX-License-Identifier: MIT
/* Why the particles' pressure reads off rho0 g d by a steady pattern (docs/validation.md, "DFSPH:
 * hydrostatic tank"). With the symmetric force F_i = -m^2 sum_j (k_i + k_j) grad W_ij (k = p / rho^2,
 * the library's scaled W_spiky), a pressure varying linearly, k_j = k_i + grad k . (x_j - x_i),
 * accelerates particle i by -(M^T grad p) / rho0 - 2 k_i sum_j m grad W_ij, where
 * M = -sum_j (m / rho0) (x_i - x_j) (x) grad W_ij is the packing's first moment: I in the continuum
 * and on the FCC lattice (the library scales W_spiky so: fcc_spiky_scale), something else on
 * another packing; the second, zeroth-order term vanishes only where the neighbourhood is
 * symmetric. At rest the per-particle pressure is the multiplier that balances the weight through
 * that operator, so where M_yy differs from one or the zeroth-order term is not zero, the
 * pressure's gradient differs from rho0 g.
 *
 * Per slice (interior particles) this reports the mean M_yy, the pairs' pressure acceleration over
 * g (1 at rest: the check that the pressure is an equilibrium), its zeroth-order part, and the
 * virial pressure, the force per area the pairs carry across a horizontal plane (Irving-Kirkwood:
 * P_i = -(rho0 m / 2) sum_j (k_i + k_j) (y_i - y_j) dW_ij/dy, = p M_yy for a uniform pressure),
 * which momentum balance ties to the weight above: an explanation of the particles' reading, not
 * a test of it. */
#include "hydrostatic_tank_moment.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "validation_util.h"

struct tank_moment {
  uint32_t bins;
  double *moment, *virial, *lift, *zeroth;
  uint32_t* count;
};

tank_moment* tank_moment_create(uint32_t bins) {
  tank_moment* t = (tank_moment*)calloc(1, sizeof(tank_moment));
  assert_non_null(t);
  t->bins = bins;
  t->moment = (double*)calloc(bins, sizeof(double));
  t->virial = (double*)calloc(bins, sizeof(double));
  t->lift = (double*)calloc(bins, sizeof(double));
  t->zeroth = (double*)calloc(bins, sizeof(double));
  t->count = (uint32_t*)calloc(bins, sizeof(uint32_t));
  assert_true(t->moment && t->virial && t->lift && t->zeroth && t->count);
  return t;
}

/* The library's W_spiky is scaled so that M = I on the FCC lattice with V = m / rho0 (the lattice's
 * poly6 volume: fcc_spiky_scale in src/core/fcc_lattice.cpp, repeated here in double). */
static double spiky_scale(double step, double h) {
  const int reach = (int)ceil(h / step) + 1;
  const double poly6 = 315.0 / (64.0 * M_PI * pow(h, 9.0)), grad = -45.0 / (M_PI * pow(h, 6.0));
  double w_sum = 0.0, moment = 0.0;
  for (int k = -reach; k <= reach; ++k)
    for (int j = -reach; j <= reach; ++j)
      for (int i = -reach; i <= reach; ++i) {
        const double r2 = step * step * (i * i + j * j + k * k);
        double r;
        if (((i + j + k) % 2 + 2) % 2 != 0 || r2 >= h * h) continue;
        w_sum += poly6 * (h * h - r2) * (h * h - r2) * (h * h - r2);
        if (r2 == 0.0) continue;
        r = sqrt(r2);
        moment += -grad * (h - r) * (h - r) * (step * i) * (step * i) / r;
      }
  return w_sum / moment;
}

/* The neighbours by a cell grid of cells h wide over the particles' bounding box. */
void tank_moment_add(tank_moment* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0, double h, double width, double bin, double step) {
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  int dims[3];
  uint32_t cells, *start, *order, *cell_of;
  const double grad = -45.0 / (M_PI * pow(h, 6.0)) * spiky_scale(step, h); /* dW/dr = grad (h - r)^2 */
  for (uint32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = fmin(lo[a], x[3 * i + a]);
      hi[a] = fmax(hi[a], x[3 * i + a]);
    }
  for (int a = 0; a < 3; ++a) dims[a] = (int)((hi[a] - lo[a]) / h) + 1;
  cells = (uint32_t)(dims[0] * dims[1] * dims[2]);
  start = (uint32_t*)calloc(cells + 1u, sizeof(uint32_t));
  order = (uint32_t*)malloc(sizeof(uint32_t) * n);
  cell_of = (uint32_t*)malloc(sizeof(uint32_t) * n);
  assert_true(start && order && cell_of);
  for (uint32_t i = 0; i < n; ++i) {
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = (int)((x[3 * i + a] - lo[a]) / h);
    cell_of[i] = (uint32_t)((c[2] * dims[1] + c[1]) * dims[0] + c[0]);
    ++start[cell_of[i] + 1u];
  }
  for (uint32_t c = 0; c < cells; ++c) start[c + 1u] += start[c];
  {
    uint32_t* fill = (uint32_t*)malloc(sizeof(uint32_t) * cells);
    assert_non_null(fill);
    for (uint32_t c = 0; c < cells; ++c) fill[c] = start[c];
    for (uint32_t i = 0; i < n; ++i) order[fill[cell_of[i]]++] = i;
    free(fill);
  }
  for (uint32_t i = 0; i < n; ++i) {
    const double xi = x[3 * i], yi = x[3 * i + 1], zi = x[3 * i + 2];
    const double ki = p[i] / ((double)rho[i] * rho[i]);
    const int l = (int)floor(yi / bin);
    int c[3];
    double moment = 0.0, virial = 0.0, lift = 0.0, zeroth = 0.0;
    if (xi < h || xi > width - h || zi < h || zi > width - h || l < 0 || l >= (int)t->bins) continue;
    for (int a = 0; a < 3; ++a) c[a] = (int)((x[3 * i + a] - lo[a]) / h);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          uint32_t cell;
          if (cx < 0 || cy < 0 || cz < 0 || cx >= dims[0] || cy >= dims[1] || cz >= dims[2]) continue;
          cell = (uint32_t)((cz * dims[1] + cy) * dims[0] + cx);
          for (uint32_t s = start[cell]; s < start[cell + 1u]; ++s) {
            const uint32_t j = order[s];
            const double d[3] = {xi - x[3 * j], yi - x[3 * j + 1], zi - x[3 * j + 2]};
            const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            double dwdy, kj;
            if (j == i || r >= h || r <= 0.0) continue;
            dwdy = grad * (h - r) * (h - r) * d[1] / r;
            kj = p[j] / ((double)rho[j] * rho[j]);
            moment -= (mass / rho0) * d[1] * dwdy;
            virial -= 0.5 * rho0 * mass * (ki + kj) * d[1] * dwdy;
            lift -= mass * (ki + kj) * dwdy;
            zeroth -= 2.0 * mass * ki * dwdy;
          }
        }
    t->moment[l] += moment;
    t->virial[l] += virial;
    t->lift[l] += lift;
    t->zeroth[l] += zeroth;
    ++t->count[l];
  }
  free(start);
  free(order);
  free(cell_of);
}

void tank_moment_print(const tank_moment* t, const double* y, double surface, double rho0, double g,
                       double h) {
  printf(
      "  per slice (interior particles, every 20 ms of the window): the pressure force's moment M_yy (1 on\n"
      "  the lattice), the pairs' pressure acceleration / g (1 at rest), its zeroth-order part\n"
      "  2 k_i sum_j m dW_ij/dy / g, the virial pressure against rho0 g (y_s - y) at the particles' y_s:\n");
  printf("  %-9s %-7s %-8s %-8s %-8s\n", "y, m", "M_yy", "accel/g", "zeroth/g", "virial");
  for (uint32_t l = 0; l < t->bins; ++l) {
    const double c = t->count[l] ? 1.0 / t->count[l] : 0.0, exact = rho0 * g * (surface - y[l]);
    if (!t->count[l]) continue;
    printf("  %-9.4f %-7.4f %-8.4f %+-8.4f %+6.2f %%%s\n", y[l], t->moment[l] * c, t->lift[l] * c / g,
           t->zeroth[l] * c / g, exact > 0.0 ? 100.0 * (t->virial[l] * c / exact - 1.0) : 0.0,
           y[l] >= h && surface - y[l] >= 2.0 * h ? "" : "  (boundary layer)");
  }
}

void tank_moment_destroy(tank_moment* t) {
  if (!t) return;
  free(t->moment);
  free(t->virial);
  free(t->lift);
  free(t->zeroth);
  free(t->count);
  free(t);
}
