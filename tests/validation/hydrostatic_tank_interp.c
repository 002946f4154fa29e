// SPDX-License-Identifier: MIT
/* The hydrostatic tank's brute-force check of its gauge reading (hydrostatic_tank_interp.h).
 *
 * The library's gauge (src/physics/probe_sampling.h) reads, over a line's points x_k,
 *   p_gauge = sum_k sum_j V_j p_j W(x_k - x_j) / sum_k sum_j V_j W(x_k - x_j),  V_j = m / rho_j,
 * a Shepard mean: it reproduces a constant field but not a linear one where the weights are not
 * symmetric about the line. For p_j = a - b y_j it reads a - b y_w exactly, y_w the same mean of
 * the particles' heights: the reading belongs to y_w, not to the line's height. This recomputes
 * the reading by hand from one state's positions, densities and pressures (the check that the
 * library computes what it says), together with y_w, the same mean with V_j = m / rho0, and the
 * fluid fraction sum_j V_j W (1 in the bulk). */
#include "hydrostatic_tank_interp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cell_grid.h"
#include "validation_util.h"

struct tank_interp {
  uint32_t bins, lines, samples;
  double width, depth, h, bin, step;
  /* per bin, summed over states: each state's line-summed ratios */
  double *p, *p_rho0, *y_w, *y_w_rho0, *fraction;
  uint32_t* states;
  /* the same on lines 2 h from the side walls, and the slices' particles within h of a side wall
   * (the band) and inside it (the interior), per state: mean pressure and height */
  double *p_inner, *p_sub, *y_sub, *band_p, *band_y, *interior_p, *interior_y;
  uint32_t *band_n, *interior_n;
  /* the 8 heights' weights K_j = sum over the slice's points of V_j W, per particle, split: with
   * q_j = p_j + rho0 g y_j (a linear p's q is constant), per state the K-weighted mean of q over the
   * interior particles less their plain mean in the slice, the band's less the interior's, the
   * band's share of K */
  double *k_weight, *d_interior, *d_band, *band_share;
};

tank_interp* tank_interp_create(uint32_t bins, double width, double depth, double h, double bin,
                                double step) {
  tank_interp* t = (tank_interp*)calloc(1, sizeof(tank_interp));
  assert_non_null(t);
  t->bins = bins;
  t->width = width;
  t->depth = depth;
  t->h = h;
  t->bin = bin;
  t->step = step;
  t->lines = (uint32_t)((width - 2.0 * h) / step) + 1u;
  /* as the library's gauge: samples h / 8 apart (world_probes.cpp), at the midpoints */
  t->samples = (uint32_t)((width - 2.0 * h) / (float)(h / 8.0));
  if (t->samples < 1u) t->samples = 1u;
  t->p = (double*)calloc(bins, sizeof(double));
  t->p_rho0 = (double*)calloc(bins, sizeof(double));
  t->y_w = (double*)calloc(bins, sizeof(double));
  t->y_w_rho0 = (double*)calloc(bins, sizeof(double));
  t->fraction = (double*)calloc(bins, sizeof(double));
  t->states = (uint32_t*)calloc(bins, sizeof(uint32_t));
  t->p_inner = (double*)calloc(bins, sizeof(double));
  t->p_sub = (double*)calloc(bins, sizeof(double));
  t->d_interior = (double*)calloc(bins, sizeof(double));
  t->d_band = (double*)calloc(bins, sizeof(double));
  t->band_share = (double*)calloc(bins, sizeof(double));
  t->y_sub = (double*)calloc(bins, sizeof(double));
  t->band_p = (double*)calloc(bins, sizeof(double));
  t->band_y = (double*)calloc(bins, sizeof(double));
  t->interior_p = (double*)calloc(bins, sizeof(double));
  t->interior_y = (double*)calloc(bins, sizeof(double));
  t->band_n = (uint32_t*)calloc(bins, sizeof(uint32_t));
  t->interior_n = (uint32_t*)calloc(bins, sizeof(uint32_t));
  assert_true(t->p && t->p_rho0 && t->y_w && t->y_w_rho0 && t->fraction && t->states && t->p_inner &&
              t->band_p && t->band_y && t->interior_p && t->interior_y && t->band_n && t->interior_n);
  return t;
}

void tank_interp_add(tank_interp* t, uint32_t n, const float* x, const float* p, const float* rho,
                     double mass, double rho0) {
  const double h = t->h, h2 = h * h, poly6 = 315.0 / (64.0 * M_PI * pow(h, 9.0));
  support_cell_grid grid;
  assert_true(support_cell_grid_build(&grid, x, n, h));
  free(t->k_weight);
  t->k_weight = (double*)calloc((size_t)n * t->bins, sizeof(double));
  assert_non_null(t->k_weight);
  for (uint32_t i = 0; i < n; ++i) {
    const double xi = x[3 * i], yi = x[3 * i + 1], zi = x[3 * i + 2];
    const int b = (int)floor(yi / t->bin);
    if (b < 0 || b >= (int)t->bins) continue;
    if (xi < h || xi > t->width - h || zi < h || zi > t->width - h) {
      t->band_p[b] += p[i];
      t->band_y[b] += yi;
      ++t->band_n[b];
    } else {
      t->interior_p[b] += p[i];
      t->interior_y[b] += yi;
      ++t->interior_n[b];
    }
  }
  /* pass 0: the library's lines; 1: lines 2 h from the side walls; 2 + s: the library's lines at
   * the slice's heights b bin + (s + 1/2) bin / 8 (the slice's height average) */
  for (uint32_t pass = 0; pass < 10; ++pass)
    for (uint32_t b = 0; b < t->bins; ++b) {
      const double margin = pass == 1 ? 2.0 * h : h;
      const double y = pass >= 2 ? (b + (pass - 2 + 0.5) / 8.0) * t->bin : (b + 0.5) * t->bin;
      const uint32_t samples = pass == 1 ? (uint32_t)((t->width - 2.0 * margin) / (h / 8.0)) : t->samples;
      const uint32_t lines = pass == 1 ? (uint32_t)((t->width - 2.0 * margin) / t->step) + 1u : t->lines;
      const double dx = (t->width - 2.0 * margin) / (samples ? samples : 1u);
      double s = 0.0, sp = 0.0, sy = 0.0, s0 = 0.0, sp0 = 0.0, sy0 = 0.0;
      if (y > t->depth || margin * 2.0 >= t->width) continue;
      for (uint32_t l = 0; l < lines; ++l)
        for (uint32_t k = 0; k < samples; ++k) {
          const double q[3] = {margin + (k + 0.5) * dx, y, margin + l * t->step};
          const uint32_t near = support_cell_grid_near(&grid, q);
          for (uint32_t e = 0; e < near; ++e) {
            const uint32_t j = grid.candidates[e];
            const double d[3] = {q[0] - x[3 * j], q[1] - x[3 * j + 1], q[2] - x[3 * j + 2]};
            const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            double w, v, v0;
            if (r2 >= h2) continue;
            w = poly6 * (h2 - r2) * (h2 - r2) * (h2 - r2);
            v = mass / rho[j] * w;
            v0 = mass / rho0 * w;
            s += v;
            if (pass >= 2) t->k_weight[(size_t)b * n + j] += v;
            sp += v * p[j];
            sy += v * x[3 * j + 1];
            s0 += v0;
            sp0 += v0 * p[j];
            sy0 += v0 * x[3 * j + 1];
          }
        }
      if (s <= 0.0) continue;
      if (pass >= 2) {
        t->p_sub[b] += sp / s / 8.0;
        t->y_sub[b] += sy / s / 8.0;
        continue;
      }
      if (pass) {
        t->p_inner[b] += sp / s;
        continue;
      }
      t->p[b] += sp / s;
      t->y_w[b] += sy / s;
      t->p_rho0[b] += sp0 / s0;
      t->y_w_rho0[b] += sy0 / s0;
      t->fraction[b] += s / ((double)t->lines * t->samples);
      ++t->states[b];
    }
  for (uint32_t b = 0; b < t->bins; ++b) {
    double kq_i = 0.0, k_i = 0.0, kq_b = 0.0, k_b = 0.0, q_plain = 0.0;
    uint32_t plain = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const double xi = x[3 * i], yi = x[3 * i + 1], zi = x[3 * i + 2], q = p[i] + rho0 * 9.81 * yi;
      const double k = t->k_weight[(size_t)b * n + i];
      const int band = xi < h || xi > t->width - h || zi < h || zi > t->width - h;
      if (band) {
        kq_b += k * q;
        k_b += k;
      } else {
        kq_i += k * q;
        k_i += k;
        if ((int)floor(yi / t->bin) == (int)b) {
          q_plain += q;
          ++plain;
        }
      }
    }
    if (k_i <= 0.0 || !plain) continue;
    t->d_interior[b] += kq_i / k_i - q_plain / plain;
    t->d_band[b] += k_b > 0.0 ? kq_b / k_b - kq_i / k_i : 0.0;
    t->band_share[b] += k_b / (k_b + k_i);
  }
  support_cell_grid_free(&grid);
}

void tank_interp_profile(const tank_interp* t, double* pressure, double* y_weighted, uint32_t* count) {
  for (uint32_t b = 0; b < t->bins; ++b) {
    const double c = t->states[b] ? 1.0 / t->states[b] : 0.0;
    pressure[b] = t->p[b] * c;
    y_weighted[b] = t->y_w[b] * c;
    count[b] = t->states[b];
  }
}

void tank_interp_print(const tank_interp* t, const double* gauge_p, double surface, double rho0, double g) {
  printf(
      "  the gauges by hand (every 0.1 s of the window; W_poly6, samples h/8 apart): p by hand against the\n"
      "  library's gauge (diff); the Shepard mean height y_w of the same weights less the line's y, and\n"
      "  the same with V = m / rho0 (lattice steps); the fluid fraction; rho0 g (y_s - y) / rho0 g (y_s -\n"
      "  y_w) - 1 (height; y_s the gauges' fit); p by hand with V = m / rho0 and on lines 2 h from the side\n"
      "  walls, against p by hand; the particles within h of a side wall (band) against the slice's "
      "interior\n"
      "  particles at the same height; and p by hand at the line's height (1 height) and averaged over 8\n"
      "  heights across the slice (8 heights) against the slice's interior particles' mean at its y_w:\n");
  printf("  %-8s %-10s %-10s %-8s %-8s %-8s %-8s %-8s %-8s %-8s %-8s %-8s %-8s\n", "y, m", "gauge, Pa",
         "by hand", "diff", "y_w-y", "(rho0)", "fraction", "height", "m/rho0", "lines 2h", "band", "1 height",
         "8 heights");
  for (uint32_t b = 0; b < t->bins; ++b) {
    const double c = t->states[b] ? 1.0 / t->states[b] : 0.0, y = (b + 0.5) * t->bin;
    const double p = t->p[b] * c, yw = t->y_w[b] * c;
    const double pb = t->band_n[b] ? t->band_p[b] / t->band_n[b] : 0.0;
    const double yb = t->band_n[b] ? t->band_y[b] / t->band_n[b] : 0.0;
    const double pi = t->interior_n[b] ? t->interior_p[b] / t->interior_n[b] : 0.0;
    const double yi = t->interior_n[b] ? t->interior_y[b] / t->interior_n[b] : 0.0;
    double band, one, eight;
    if (!t->states[b]) continue;
    /* moved to a common height along rho0 g */
    band = pi > 0.0 ? (pb + rho0 * g * (yb - yi)) / pi - 1.0 : 0.0;
    one = pi > 0.0 ? p / (pi - rho0 * g * (yw - yi)) - 1.0 : 0.0;
    eight = pi > 0.0 ? t->p_sub[b] * c / (pi - rho0 * g * (t->y_sub[b] * c - yi)) - 1.0 : 0.0;
    printf(
        "  %-8.4f %-10.1f %-10.1f %+6.3f%% %+7.4f  %+7.4f  %-8.4f %+6.3f%% %+6.3f%% %+6.3f%% %+6.2f%% "
        "%+6.2f%% %+6.2f%% %+6.2f%% %+6.2f%% %5.1f%%\n",
        y, gauge_p[b], p, gauge_p[b] != 0.0 ? 100.0 * (p / gauge_p[b] - 1.0) : 0.0, (yw - y) / t->step,
        (t->y_w_rho0[b] * c - y) / t->step, t->fraction[b] * c,
        surface - yw > 0.0 ? 100.0 * ((surface - y) / (surface - yw) - 1.0) : 0.0,
        100.0 * (t->p_rho0[b] * c / p - 1.0), 100.0 * (t->p_inner[b] * c / p - 1.0), 100.0 * band,
        100.0 * one, 100.0 * eight, 100.0 * t->d_interior[b] * c / pi, 100.0 * t->d_band[b] * c / pi,
        100.0 * t->band_share[b] * c);
  }
}

void tank_interp_destroy(tank_interp* t) {
  if (!t) return;
  free(t->p);
  free(t->p_rho0);
  free(t->y_w);
  free(t->y_w_rho0);
  free(t->fraction);
  free(t->states);
  free(t->p_inner);
  free(t->p_sub);
  free(t->k_weight);
  free(t->d_interior);
  free(t->d_band);
  free(t->band_share);
  free(t->y_sub);
  free(t->band_p);
  free(t->band_y);
  free(t->interior_p);
  free(t->interior_y);
  free(t->band_n);
  free(t->interior_n);
  free(t);
}
