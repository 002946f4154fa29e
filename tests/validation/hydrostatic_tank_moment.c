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
 * a test of it.
 *
 * With SPH_DFSPH_CORRECTED_GRADIENT the solves use another operator (src/physics/
 * dfsph_gradient_correction.h): the sum S_i = sum_j m (k_i + k_j) grad W_ij becomes
 * S_i + w (L_i (S_i - 2 (1 - beta) k_i Z_i) - S_i), L_i = B_i^-1 (B_i = M above, the full tensor),
 * Z_i = sum_j m grad W_ij, beta = 0.2, w the fade from 0 at trace(B)/3 <= 0.94 to 1 at >= 0.99. Its
 * moment is then w I + (1 - w) B (M_yy: that one's yy), its acceleration -S_i so corrected, and its
 * zeroth-order part -(1 - w) 2 k_i Z_i - w 2 beta k_i L_i Z_i; those are printed (the virial stays the
 * pairs' (k_i + k_j) form, which the corrected operator no longer is). The constants are the
 * library's, repeated here. */
#include "hydrostatic_tank_moment.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cell_grid.h"
#include "validation_util.h"

struct tank_moment {
  uint32_t bins;
  int corrected;
  double *moment, *virial, *lift, *zeroth;
  uint32_t* count;
};

tank_moment* tank_moment_create(uint32_t bins, int corrected) {
  tank_moment* t = (tank_moment*)calloc(1, sizeof(tank_moment));
  assert_non_null(t);
  t->bins = bins;
  t->corrected = corrected;
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

/* The corrected operator's M_yy, acceleration and zeroth-order part from B (the full moment), the
 * pairs' sum S = sum_j m (k_i + k_j) grad W_ij and Z = sum_j m grad W_ij, as corrected_pressure_sum
 * (src/physics/dfsph_gradient_correction.h) forms them; left as they are where the fade is zero or
 * det B is not positive, as there. */
static void corrected_operator(double b[3][3], const double sum[3], const double z[3], double ki,
                               double* moment, double* lift, double* zeroth) {
  const double full = 0.99, none = 0.94, kept = 0.2; /* DfsphGradientCorrection's */
  const double t = (b[0][0] + b[1][1] + b[2][2]) / 3.0;
  const double w = fmin(fmax((t - none) / (full - none), 0.0), 1.0);
  double inv[3][3], det, r[3], lr[3], lz[3];
  if (w <= 0.0) return;
  inv[0][0] = b[1][1] * b[2][2] - b[1][2] * b[2][1];
  inv[0][1] = b[0][2] * b[2][1] - b[0][1] * b[2][2];
  inv[0][2] = b[0][1] * b[1][2] - b[0][2] * b[1][1];
  inv[1][0] = b[1][2] * b[2][0] - b[1][0] * b[2][2];
  inv[1][1] = b[0][0] * b[2][2] - b[0][2] * b[2][0];
  inv[1][2] = b[0][2] * b[1][0] - b[0][0] * b[1][2];
  inv[2][0] = b[1][0] * b[2][1] - b[1][1] * b[2][0];
  inv[2][1] = b[0][1] * b[2][0] - b[0][0] * b[2][1];
  inv[2][2] = b[0][0] * b[1][1] - b[0][1] * b[1][0];
  det = b[0][0] * inv[0][0] + b[0][1] * inv[1][0] + b[0][2] * inv[2][0];
  if (!(det > 0.0)) return;
  for (int a = 0; a < 3; ++a) r[a] = sum[a] - 2.0 * (1.0 - kept) * ki * z[a];
  for (int a = 0; a < 3; ++a) {
    lr[a] = (inv[a][0] * r[0] + inv[a][1] * r[1] + inv[a][2] * r[2]) / det;
    lz[a] = (inv[a][0] * z[0] + inv[a][1] * z[1] + inv[a][2] * z[2]) / det;
  }
  *moment = w + (1.0 - w) * b[1][1];
  *lift = -(sum[1] + (lr[1] - sum[1]) * w);
  *zeroth = -((1.0 - w) * 2.0 * ki * z[1] + w * 2.0 * kept * ki * lz[1]);
}

/* The neighbours by a cell grid of cells h wide over the particles' bounding box. */
void tank_moment_add(tank_moment* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0, double h, double width, double bin, double step) {
  support_cell_grid grid;
  const double grad = -45.0 / (M_PI * pow(h, 6.0)) * spiky_scale(step, h); /* dW/dr = grad (h - r)^2 */
  assert_true(support_cell_grid_build(&grid, x, n, h));
  for (uint32_t i = 0; i < n; ++i) {
    const double xi = x[3 * i], yi = x[3 * i + 1], zi = x[3 * i + 2];
    const double ki = p[i] / ((double)rho[i] * rho[i]);
    const int l = (int)floor(yi / bin);
    double moment = 0.0, virial = 0.0, lift = 0.0, zeroth = 0.0;
    double b[3][3] = {{0.0}}, sum[3] = {0.0, 0.0, 0.0}, z[3] = {0.0, 0.0, 0.0};
    if (xi < h || xi > width - h || zi < h || zi > width - h || l < 0 || l >= (int)t->bins) continue;
    {
      const double q[3] = {xi, yi, zi};
      const uint32_t near = support_cell_grid_near(&grid, q);
      for (uint32_t e = 0; e < near; ++e) {
        const uint32_t j = grid.candidates[e];
        const double d[3] = {xi - x[3 * j], yi - x[3 * j + 1], zi - x[3 * j + 2]};
        const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        double dwdy, kj;
        if (j == i || r >= h || r <= 0.0) continue;
        dwdy = grad * (h - r) * (h - r) * d[1] / r;
        kj = p[j] / ((double)rho[j] * rho[j]);
        for (int a = 0; a < 3; ++a) {
          const double g = mass * grad * (h - r) * (h - r) * d[a] / r; /* m grad W_ij, component a */
          for (int c2 = 0; c2 < 3; ++c2) b[a][c2] -= g * d[c2] / rho0;
          sum[a] += (ki + kj) * g;
          z[a] += g;
        }
        moment -= (mass / rho0) * d[1] * dwdy;
        virial -= 0.5 * rho0 * mass * (ki + kj) * d[1] * dwdy;
        lift -= mass * (ki + kj) * dwdy;
        zeroth -= 2.0 * mass * ki * dwdy;
      }
    }
    if (t->corrected) corrected_operator(b, sum, z, ki, &moment, &lift, &zeroth);
    t->moment[l] += moment;
    t->virial[l] += virial;
    t->lift[l] += lift;
    t->zeroth[l] += zeroth;
    ++t->count[l];
  }
  support_cell_grid_free(&grid);
}

void tank_moment_print(const tank_moment* t, const double* y, double surface, double rho0, double g,
                       double h) {
  printf(
      "  per slice (interior particles, every 20 ms of the window; %s): the pressure force's moment M_yy (1 "
      "on\n"
      "  the lattice), the pairs' pressure acceleration / g (1 at rest), its zeroth-order part\n"
      "  2 k_i sum_j m dW_ij/dy / g, the virial pressure against rho0 g (y_s - y) at the particles' y_s:\n",
      t->corrected ? "the corrected operator the run uses" : "the symmetric operator the run uses");
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
