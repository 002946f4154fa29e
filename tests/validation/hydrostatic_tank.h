// SPDX-License-Identifier: MIT
/* The hydrostatic tank's run (test_hydrostatic_tank.c's cases): water at rest in a closed box,
 * its interior's pressure against the exact equilibrium of the solver's equation of state
 * (hydrostatic_tank.c says what is compared and why). */
#ifndef SPH_VALIDATION_HYDROSTATIC_TANK_H
#define SPH_VALIDATION_HYDROSTATIC_TANK_H

#include <stdint.h>

#include "sph_c.h"

typedef struct tank_case {
  const char* name;
  sph_equation_of_state eos; /* the weakly compressible solver's; unused by DFSPH */
  sph_solver solver;
  uint32_t features;     /* added to the world's (SPH_FEATURE_BOUNDARY_DENSITY) */
  double bound;          /* the interior's worst relative pressure error */
  uint32_t width_layers; /* lattice layers across the tank in x and z */
  uint32_t depth_layers; /* lattice layers of water */
  double step;           /* lattice step (spacing / sqrt 2), m */
  double seconds;        /* simulated time */
  float dt_max;          /* the step's ceiling, s (0: the library's default, 1 ms) */
  float dt_min;          /* the step's floor, s (0: the library's default, 1e-6 s); dt_min = dt_max pins
                            every substep (docs/physics.md, "How a frame splits into substeps") */
  float density_error;   /* DFSPH's density-solve bound (0: the library's default, 0.1 %) */
  uint32_t dfsph_flags;  /* sph_dfsph_params.flags (SPH_DFSPH_CORRECTED_GRADIENT) */
  /* The settling experiments (docs/validation.md, "DFSPH: hydrostatic tank"); 0 = as before. */
  float frame;           /* frame length, s (0: 0.02); one substep's (dt_max) samples every substep */
  double window;         /* the averaged share of the run (0: the second half) */
  double damp_until;     /* s: until then every velocity is zeroed each 0.1 s (kinetic damping) */
  float kernel_spacings; /* the kernel radius in particle spacings (0: the library's default, 1.8) */
  int gauges;            /* 1: also read the pressure through the library's gauges and report each
                            particle's scatter (hydrostatic_tank_gauges.c) */
} tank_case;

/* Runs the case: the pressure profile, the rest and the floor asserted, one line of results
 * written to the case's file (validation_open_output). */
void run_tank(const tank_case* tc);

#endif /* SPH_VALIDATION_HYDROSTATIC_TANK_H */
