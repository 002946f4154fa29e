// SPDX-License-Identifier: MIT
#include "hydrostatic_tank_profile.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "validation_util.h"

double exact_pressure(sph_equation_of_state eos, double k, double c, double rho0, double d) {
  if (d <= 0.0) return 0.0;
  if (eos == EOS_INCOMPRESSIBLE) return rho0 * GRAVITY * d;
  if (eos == SPH_EOS_TAIT) {
    const double b = rho0 * c * c / 7.0;
    return b * (pow(1.0 + 6.0 * GRAVITY * d / (c * c), 7.0 / 6.0) - 1.0);
  }
  return k * rho0 * (exp(GRAVITY * d / k) - 1.0);
}

int interior_slice(const profile_model* m, double y, double ys) { return y >= m->h && ys - y >= 2.0 * m->h; }

profile_fit fit_profile(const profile_model* m, double top_layer, uint32_t bins, const double* p,
                        const double* y, const double* rho, const uint32_t* count, const char* label) {
  profile_fit fit = {0.0, 0.0, 0.0, 0};
  double best_cost = 1e30;
  for (int s = -400; s <= 400; ++s) {
    const double ys = top_layer + 0.5 * m->step + s * (2.0 * m->h / 400.0);
    double cost = 0.0;
    for (uint32_t l = 0; l < bins; ++l) {
      double e;
      if (count[l] == 0 || !interior_slice(m, y[l], ys)) continue;
      e = p[l] / exact_pressure(m->eos, m->k, m->c, m->rho0, ys - y[l]) - 1.0;
      cost += e * e;
    }
    if (cost < best_cost) {
      best_cost = cost;
      fit.surface = ys;
    }
  }
  printf("  %s: fitted surface y_s = %.4f m (y_s - top = %.2f h)\n", label, fit.surface,
         (fit.surface - top_layer) / m->h);
  printf("  %-9s %-9s %-11s %-11s %-8s %-9s\n", "y, m", "depth, m", "p, Pa", "p exact, Pa", "error",
         "rho/rho0-1");
  for (uint32_t l = 0; l < bins; ++l) {
    double exact, e;
    int interior;
    if (count[l] == 0) continue;
    exact = exact_pressure(m->eos, m->k, m->c, m->rho0, fit.surface - y[l]);
    e = exact > 0.0 ? p[l] / exact - 1.0 : 0.0;
    interior = interior_slice(m, y[l], fit.surface);
    printf("  %-9.4f %-9.4f %-11.1f %-11.1f %+6.2f %% ", y[l], fit.surface - y[l], p[l], exact, 100.0 * e);
    if (rho)
      printf("%+7.3f %%", 100.0 * (rho[l] / m->rho0 - 1.0));
    else
      printf("%9s", "");
    printf("%s\n", interior ? "" : "  (boundary layer, not compared)");
    if (!interior) continue;
    if (fabs(e) > fit.worst) fit.worst = fabs(e);
    fit.mean += fabs(e);
    ++fit.used;
  }
  fit.mean /= fit.used ? fit.used : 1;
  printf("  %s: interior slices %u: mean |error| %.2f %%, worst %.2f %%\n", label, fit.used, 100.0 * fit.mean,
         100.0 * fit.worst);
  return fit;
}

void particle_scatter(const profile_model* m, const profile_fit* fit, uint32_t n, uint32_t bins, double bin,
                      const double* p_sum, const double* y_sum, const uint8_t* inside, int frames) {
  double* sum = (double*)calloc(bins, sizeof(double));
  double* sum2 = (double*)calloc(bins, sizeof(double));
  uint32_t* count = (uint32_t*)calloc(bins, sizeof(uint32_t));
  assert_true(sum && sum2 && count && frames > 0);
  for (uint32_t i = 0; i < n; ++i) {
    const double y = y_sum[i] / frames, p = p_sum[i] / frames;
    const int l = (int)floor(y / bin);
    double e;
    if (!inside[i] || l < 0 || l >= (int)bins || !interior_slice(m, y, fit->surface)) continue;
    e = p / exact_pressure(m->eos, m->k, m->c, m->rho0, fit->surface - y) - 1.0;
    sum[l] += e;
    sum2[l] += e * e;
    ++count[l];
  }
  printf("  per particle (its window mean, interior particles only):\n  %-6s %-5s %-9s %-9s %-9s\n", "slice",
         "N", "mean", "scatter", "std err");
  for (uint32_t l = 0; l < bins; ++l) {
    double mean, sd;
    if (count[l] < 2) continue;
    mean = sum[l] / count[l];
    sd = sqrt(fmax(sum2[l] / count[l] - mean * mean, 0.0) * count[l] / (count[l] - 1));
    printf("  %-6u %-5u %+6.2f %%  %6.2f %%  %6.2f %%\n", l, count[l], 100.0 * mean, 100.0 * sd,
           100.0 * sd / sqrt((double)count[l]));
  }
  free(sum);
  free(sum2);
  free(count);
}
