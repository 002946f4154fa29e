// SPDX-License-Identifier: MIT
/* Scenes that several C-API tests measure, built once: the collapsing column's momentum balance
 * (test_collider_loads.c on the weakly compressible solver, test_dfsph_loads.c on DFSPH), the
 * fixed box submerged in a tank (the same two) and the resting tank with its probes
 * (test_probes.c, test_dfsph_loads.c). The scenes themselves are
 * tests/support's (support_collapsing_column, support_resting_tank); each test keeps its bounds,
 * its averaging and its messages. */
#ifndef SPH_CAPI_SCENES_H
#define SPH_CAPI_SCENES_H

#include "capi_test.h"

/* ---- the collapsing column's momentum balance ------------------------------------------------ */
typedef struct capi_momentum_balance {
  uint32_t count;         /* particles */
  double fluid_change[3]; /* the fluid's momentum change over the run, N s */
  double impulse[3];      /* the impulses the tank received (sph_collider_loads), N s */
  double weight_impulse;  /* gravity's on the fluid (y), N s */
  double time;            /* s, the frames' sum of the loads' frame times */
  double error;           /* |dP + J - gravity's| / |gravity's| */
} capi_momentum_balance;

/* support_collapsing_column (free slip) in a world of `def` (with SPH_FEATURE_COLLIDER_LOADS; a
 * capacity of 0: the column's), 15 frames of 0.02 s: the fluid's momentum change plus the
 * impulses the walls received against gravity's impulse (9.81 m/s^2, the default). The pair
 * forces cancel in pairs, so what is left is rounding. dfsph_flags and dfsph_linear_solver (DFSPH;
 * 0: the defaults): sph_dfsph_params.flags and .linear_solver for the run. */
capi_momentum_balance capi_collapse_momentum_balance(const sph_world_def* def, uint32_t dfsph_flags,
                                                     uint32_t dfsph_linear_solver);

/* ---- the resting tank and its probes --------------------------------------------------------- */
#define CAPI_RESTING_WIDTH 0.12 /* m, the tank's and the water's, in x and z */
#define CAPI_RESTING_DEPTH 0.24 /* m, the water's (24 layers) */
#define CAPI_RESTING_PROBES 4
/* The point probes' heights on the centre line: 4, 8, 12 and 16 cm. */
extern const double capi_resting_heights[CAPI_RESTING_PROBES];

typedef struct capi_resting_tank {
  support_world w;
  sph_sdf* sdf;
  uint32_t count;
  sph_probe_id probes[CAPI_RESTING_PROBES]; /* at capi_resting_heights, every substep sampled */
  sph_probe_id gauge;                       /* up the centre from 3 cm below the floor, 0.48 m */
} capi_resting_tank;

/* support_resting_tank in a world of `def` (a capacity of 0: the water's) and `params` (NULL:
 * the defaults), then the point probes and the gauge (sampled by `gauge_sampling`), in that
 * order (a test's further probes come after them). */
void capi_resting_tank_open(capi_resting_tank* t, const sph_world_def* def, const sph_world_params* params,
                            sph_probe_sampling gauge_sampling);
void capi_resting_tank_close(capi_resting_tank* t);

/* ---- the weight above: the resting tank's hydrostatic reference ------------------------------ */
/* The film the walls' calibration keeps free of water at every wall, (spacing - step) / 2 at the
 * 1 cm step (docs/validation.md, "Loads on a hydrostatic tank's side wall"). */
#define CAPI_RESTING_FILM (0.5 * (1.4142135623730951 - 1.0) * 0.01)
/* The area the resting tank's water stands on: the tank's inner width less a film at each side
 * wall, squared. Measured: the centre's gauge reads the water's mass over this area 0.3-1.6 % low
 * (WCSPH, 19 draws; the middle's water a little lighter than the mean), over the tank's inner area
 * 6.9 % high (docs/validation.md, "The resting tank's probes against the weight above"). */
double capi_resting_water_area(void);
/* Adds to kernel[i] and slab[i] (i < n) the number of the world's particles above heights[i], a
 * particle straddling a height counted in part: by the SPH interpolant's own column (`kernel`: the
 * share of the particle's mass in the poly6 kernel of radius h the probes sample with, integrated
 * over the horizontal plane, that lies above the height) and as a slab one lattice step thick about
 * its centre (`slab`; either may be NULL). Times the particle mass and g over the water's area:
 * the weight above per unit area, the pressure hydrostatics asks for. */
void capi_count_above(const sph_world* world, double h, const double* heights, int n, double* kernel,
                      double* slab);

/* ---- a fixed box submerged in a tank ---------------------------------------------------------- */
#define CAPI_SUBMERGED_HALF 0.03 /* m, the box's half side */

typedef struct capi_submerged_box {
  support_world w;
  sph_sdf* tank_sdf;
  sph_sdf* box_sdf;
  sph_collider_id box;
  uint32_t count; /* particles */
} capi_submerged_box;

/* A box of 6 x 6 x 6 cm fixed with its centre 8 cm above the floor of a tank 16 x 16 cm (40 cm
 * high), water filled around it to 20 cm: 16 x 20 x 16 layers of 1 cm less the points within
 * half a layer of the box. A world of `def` (a capacity of 0: the water's) and `params` (NULL:
 * the defaults); the tank, the box, then the water. */
void capi_submerged_box_open(capi_submerged_box* s, const sph_world_def* def, const sph_world_params* params);
void capi_submerged_box_close(capi_submerged_box* s);

/* Steps `frames` frames of 0.02 s; from frame `first_averaged` on, the collider's force averaged
 * over the frames' times (sum of F dt over sum of dt), N. */
void capi_mean_force(sph_world* world, sph_collider_id collider, int frames, int first_averaged,
                     double force[3]);

#endif /* SPH_CAPI_SCENES_H */
