// SPDX-License-Identifier: MIT
// Face-centred cubic lattice points (the thesis's "tetrahedral lattice"): the points of a
// cubic grid of step spacing/sqrt(2) whose integer coordinates sum to an even number, so
// every point has 12 nearest neighbours at exactly `spacing`.
#pragma once

#include <stdint.h>

#include <vector>

#include "../physics/vec3.h"
#include "host_memory.h"

namespace sph {

// Exactly the number of points fcc_points_in_box returns, computed without generating them,
// so a fill that cannot fit is refused before anything is allocated.
uint64_t fcc_box_point_count(Vec3 min, Vec3 max, float spacing);
// The volume estimate of the points in a sphere (sqrt(2) / spacing^3 per unit volume).
double fcc_sphere_point_estimate(float radius, float spacing);

// Points at least spacing/2 inside each face of [min, max].
HostVector<Vec3> fcc_points_in_box(Vec3 min, Vec3 max, float spacing);
// Points with |p - center| <= radius; the centre is a lattice point.
HostVector<Vec3> fcc_points_in_sphere(Vec3 center, float radius, float spacing);

// The particle mass at which an infinite FCC lattice at `spacing` has density rest_density
// under W_poly6 with radius kernel_radius (sum over the lattice computed in double).
float fcc_rest_mass(float spacing, float kernel_radius, float rest_density);

// The density's self term w0 (1/m^3) for particles of `mass`: rest_density / mass minus the sum
// of W_spiky over the lattice neighbours (r < kernel_radius, the particle itself excluded), so
// that m (w0 + sum_{j != i} W_spiky) is rest_density on the infinite lattice at `spacing`
// (density.h says why the pair terms use W_spiky). Positive for kernel_radius in [1, 5] x
// spacing (0.36 / V at the default 1.8, V = spacing^3 / sqrt 2 the volume per particle).
float fcc_density_self_weight(float spacing, float kernel_radius, float rest_density, float mass,
                              float spiky_scale);

// The factor that makes W_spiky (the density's pair kernel and the pressure force's gradient)
// exact to first order on the FCC lattice: 1 / (V sum_j x_j |dW/dx|), V = m / rho0 the rest
// volume. The continuous kernel gives the moment 1; the lattice at h = 1.8 spacings only 0.899,
// so an unscaled pressure force is 10 % weak against a pressure gradient (a tank at rest then
// carries a pressure profile about 10 % steeper than rho g) and the summed density answers
// a uniform compression dV/V with only 0.899 dV/V. Scaling W by this factor (and deriving the
// self term with it) corrects both and keeps the force the gradient of the density's energy.
// 1.113 at 1.8 spacings, 1.054 at 2, 1.016 at 2.5.
float fcc_spiky_scale(float spacing, float kernel_radius);

// The neighbours of a particle of the infinite lattice: points closer than kernel_radius, the
// particle itself excluded (42 at the default 1.8 spacings).
uint32_t fcc_neighbor_count(float spacing, float kernel_radius);

// The surface integral of the particle-sampled colour gradient (surface tension's smoothed delta
// function): sum over the particles of a flat free surface of the FCC lattice of (m / rho0)
// (|grad c_i| - threshold) per unit area, over the particles where that is positive, with
// c = sum (m / rho0) W_poly6. The continuous delta integrates to 1 across the interface, but the
// particles sample only the fluid side of it, so this is about 0.45 at h = 1.8 spacings.
// Averaged over the (100), (110) and (111) faces (they differ by about 5 %).
double fcc_surface_delta_integral(float spacing, float kernel_radius, float threshold);

// The boundary density's calibration (physics/boundary_density.h): a wall's share is
// rho_b = m scale Phi_flat(d + offset), the continuous share of the kernel beyond the wall moved
// `offset` into the solid, d the particle's distance from the wall. Both are fitted to a wall
// along the lattice's (100) plane (the face a box fill puts against axis-aligned walls) at the
// first layer, spacing/2 from the wall (as fcc_points_in_box places it): the value is the sum of
// the world's density kernel s W_spiky over the half lattice the wall takes away (so that layer
// reads rho0), and the slope twice that sum's slope along the normal (so that a fluid at uniform
// pressure is in equilibrium there under the wall's force, -(p / rho^2) grad rho_b, which is the
// gradient of the fluid's energy: the fluid's own pairs push the first layer towards the wall by
// 2 (p / rho^2) times the missing sum's slope, both particles of a pair counting it). At
// h = 1.8 spacings: scale = 12.0 rho0 / m, offset = 0.49 spacings.
struct BoundaryCalibration {
  double scale;   // 1/m^3
  double offset;  // m
};
BoundaryCalibration fcc_boundary_calibration(float spacing, float kernel_radius);

// Surface tension's cohesion (physics/surface_tension.h) on the FCC lattice at `spacing`, per
// unit gamma m^2 (so both scale with the world's gamma and particle mass):
// - surface_energy: half the work, per unit area, to pull two lattice half-spaces apart along a
//   lattice plane, sum_{i in A, j in B} Phi(r_ij) / (2 area) with Phi(r) = int_r^h C, i.e. the
//   cohesion's share of sigma (J/m^2); averaged over the (100), (110) and (111) faces;
// - bulk_pressure: the pressure the equation of state must hold in the bulk against the
//   attraction, the virial (n / 6) sum_j C(r_j) r_j over one particle's neighbours (n the
//   number density); a drop's core holds this plus its Laplace pressure.
struct CohesionLattice {
  double surface_energy;
  double bulk_pressure;
};
CohesionLattice fcc_cohesion_lattice(float spacing, float kernel_radius);

}  // namespace sph
