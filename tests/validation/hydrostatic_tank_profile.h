// SPDX-License-Identifier: MIT
/* The hydrostatic tank's profile: the exact equilibrium of the solver's equation of state, and
 * the comparison of a pressure reading against it (hydrostatic_tank.c says what is compared and
 * why).
 *
 * The exact equilibrium: dp/dd = rho g at depth d, with p(0) = 0 at the free surface.
 *   ideal gas p = k (rho - rho0):         p(d) = k rho0 (exp(g d / k) - 1)
 *   Tait p = B ((rho / rho0)^7 - 1),
 *        B = rho0 c^2 / 7:                (rho / rho0)^6 = 1 + 6 g d / c^2,
 *                                         p(d) = B ((1 + 6 g d / c^2)^(7/6) - 1)
 *   DFSPH (incompressible):              p(d) = rho0 g d */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_PROFILE_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_PROFILE_H

#include <stdint.h>

#include "sph_c.h"

#define GRAVITY 9.81

/* DFSPH's profile (not an sph_equation_of_state: the solver is incompressible). */
#define EOS_INCOMPRESSIBLE ((sph_equation_of_state)0x7fff)

/* The profile compared: its equation of state, the stiffness k (ideal gas), the speed of sound c
 * (Tait), rho0, the kernel radius h and the lattice step. */
typedef struct profile_model {
  sph_equation_of_state eos;
  double k, c, rho0, h, step;
} profile_model;

/* The fitted surface height y_s, the interior slices' mean and worst |relative error|, and how
 * many slices were compared. */
typedef struct profile_fit {
  double surface, mean, worst;
  uint32_t used;
} profile_fit;

/* The exact pressure at depth d (0 above the surface). */
double exact_pressure(sph_equation_of_state eos, double k, double c, double rho0, double d);

/* Whether height y is interior for surface ys: above the floor's kernel radius, 2 h below ys. */
int interior_slice(const profile_model* m, double y, double ys);

/* The interior slices' comparison of one pressure reading (per slice: mean pressure p, mean
 * height y, density rho or NULL, particle count) against the profile: the surface height y_s
 * fitted (least squares of the relative error, within 2 h around the top particle layer's
 * top), then each slice's error; the table printed under `label`. */
profile_fit fit_profile(const profile_model* m, double top_layer, uint32_t bins, const double* p,
                        const double* y, const double* rho, const uint32_t* count, const char* label);

/* Each particle's pressure averaged over the window (sums over `frames` frames), against the
 * profile at its mean height, printed per slice `bin` thick: the particles' mean error, their
 * scatter and its standard error (scatter / sqrt N). A slice's error that matches its standard
 * error is the sampling of a steady per-particle pattern by the slice's few particles, and falls
 * as 1 / sqrt(particles per slice). */
void particle_scatter(const profile_model* m, const profile_fit* fit, uint32_t n, uint32_t bins, double bin,
                      const double* p_sum, const double* y_sum, const uint8_t* inside, int frames);

#endif
