// SPDX-License-Identifier: MIT
// Walls in the density (SPH_FEATURE_BOUNDARY_DENSITY): a collider's solid counts in every
// particle's density sum, as a density map (Koschier & Bender 2017, "Density maps for improved
// SPH boundary handling"), so particles at a wall read the bulk's density instead of 70-80 % of
// it, and the wall pushes back through the pressure force.
//
// The boundary's share of particle i's density is
//     rho_b(x_i) = K Phi(x_i),   Phi(x) = int over the solid moved back by delta of W_spiky(|x - y|, h) dy,
// Phi in [0, 1] the share of the kernel's unit mass inside the solid whose surface is moved delta
// into it (the level set sigma phi = -delta of the collider's SDF). K (kg/m^3) and delta (m) are
// calibrated on the FCC lattice (core/fcc_lattice.h, fcc_boundary_calibration): the fluid's
// density is a discrete sum, rho_i = m (w0 + sum_{j != i} s W_spiky(r_ij)), and at a wall along
// the lattice's (100) plane the first layer (spacing/2 from the wall) misses the sum over the half
// lattice beyond it; K and delta make rho_b equal that sum there and its slope twice the sum's
// (the fluid's pairs, each counted by both its particles, push the layer towards the wall by
// that much at uniform pressure). 12.0 rho0 and 0.49 spacings at h = 1.8 spacings; docs/physics.md.
//
// Phi is sampled, per collider, as the flat-wall value of the collider's own signed distance
// plus a correction stored per SDF voxel (boundary_map.h):
//     Phi(x) = Phi_flat(sigma (phi(x) - L)) + sigma dPhi_L(x),   L = -sigma delta,
//     grad Phi = the exact gradient of that sampled Phi,
// phi the SDF (trilinear), sigma the collider's sign (-1 for an inverted collider, whose solid is
// the complement: Phi = 1 - the share of {phi < L}), Phi_flat the closed-form half-space share
// (boundary_integrals.h), and the correction for the level L what curvature, corners and thin
// walls add (a solid's map, L < 0, corrects the distance instead: Phi = Phi_flat(phi - L + e(x)),
// e the map's offset; map_corrects_distance says why), computed per asset, kernel radius and level by a
// quadrature over the solid (value and gradient per voxel) and interpolated as a cubic Hermite of both. The
// gradient being that of the sampled value makes the wall's force conservative (local_boundary_share). A flat
// wall is exact at any voxel size (the trilinear SDF of a plane is the plane).
//
// The pressure force of the wall (Akinci et al. 2012 with the wall's share as the boundary
// "particles"): a_i = -(p_i / rho_i^2) grad rho_b(x_i). It is minus the gradient of the fluid's
// internal energy sum_i m e(rho_i) through rho_b (de/drho = p / rho^2), as the symmetric pair force
// is through the pairs, so a static wall does no net work on the fluid (a mirrored pressure,
// 2 p_i / rho_i^2, is not a gradient: measured, it kept a tank at rest sloshing at 0.3-0.8 J where
// this one settles). Its reaction on the collider is +m (p_i / rho_i^2) grad rho_b(x_i) per
// particle and collider (collider_boundary_share keeps each collider's share apart for a
// reduction of loads).
//
// Interface for the solvers (the density pass and DFSPH): per particle, boundary_share() sums the
// colliders' shares at the particle's position and the stage's time; the density pass adds
// .density to rho_i and stores pack_boundary() in the per-particle array kArrayBoundaryGradient
// (Scratch, sorted order, one Float4: grad rho_b and the wall's velocity flux), which the force
// pass and the DFSPH solves read:
//   - WCSPH force:        a_i += boundary_pressure_acceleration(record, p_i, 1 / rho_i)
//   - DFSPH alpha:        sum_j m grad W_ij + boundary_gradient(record) in the squared sum
//   - DFSPH density rate: d rho_i / dt += boundary_density_rate(record, v_i)
//                         (sum over colliders of (v_i - v_b) . grad rho_b)
//   - DFSPH velocity:     v_i -= dt (kappa_i / rho_i) boundary_gradient(record)
//                         (the wall's share with kappa_i alone, as the boundary has no kappa)
#pragma once

#include <stdint.h>

#include "boundary_integrals.h"
#include "collider_response.h"
#include "float4_types.h"
#include "particle_array_spec.h"
#include "world_shape.h"

namespace sph {

constexpr const char* kArrayBoundaryGradient = "boundary_gradient";  // boundary density, Float4

struct BoundaryDensity {
  static constexpr const char* kName = "boundary_density";
  // (grad rho_b, v_b . grad rho_b) of the last density pass, in sorted order.
  static constexpr ParticleArraySpec kArrays[] = {
      {kArrayBoundaryGradient, sizeof(Float4), ParticleArrayRole::Scratch, 1, nullptr, nullptr}};

  struct Constants {
    float density_scale;   // K, kg/m^3: rho_b = K Phi
    float kernel_radius;   // h, m (the maps are made for it)
    float surface_offset;  // delta, m: Phi is the share of the solid moved this far into it
  };

  static Constants make_constants(const WorldShape& shape, const LatticeSums& lattice) {
    double scale = 0.0, offset = 0.0;
    lattice.boundary_calibration(shape.particle_spacing, shape.kernel_radius, &scale, &offset);
    Constants c;
    c.density_scale = static_cast<float>(scale * static_cast<double>(shape.particle_mass));
    c.kernel_radius = shape.kernel_radius;
    c.surface_offset = static_cast<float>(offset);
    return c;
  }

  // The SDF level whose solid a collider of this sign counts (the map is made for it).
  SPH_HD static float map_level(const Constants& c, float sign) { return -sign * c.surface_offset; }
};

// One collider's share of a particle's density, or the sum of several.
struct BoundaryShare {
  float density;        // rho_b(x), kg/m^3
  Vec3 gradient;        // grad rho_b(x), kg/m^4, world frame (points into the solid)
  float velocity_flux;  // v_b(x) . grad rho_b(x), kg/(m^3 s): the wall's motion (0 when static)
};

// Float4 arithmetic for the trilinear interpolation of the map (sdf_sampling.h's lerp_value).
SPH_HD Float4 operator+(const Float4& a, const Float4& b) {
  return Float4{a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
}
SPH_HD Float4 operator-(const Float4& a, const Float4& b) {
  return Float4{a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w};
}
SPH_HD Float4 operator*(const Float4& a, float s) { return Float4{a.x * s, a.y * s, a.z * s, a.w * s}; }

SPH_HD BoundaryShare no_boundary_share() { return BoundaryShare{0.0f, Vec3{0.0f, 0.0f, 0.0f}, 0.0f}; }

// The trilinear interpolant's value and its exact gradient (index space) in one cell, from the 8
// corners, with the corners' range.
struct TrilinearGradient {
  float value;
  Vec3 gradient;  // d/d(index)
  float lo, hi;   // the smallest and largest corner
};

SPH_HD TrilinearGradient trilinear_with_gradient(const float* data, const SdfGridView& g,
                                                 const TrilinearCell& c) {
  const int32_t di = g.nx > 1 ? 1 : 0, dj = g.ny > 1 ? g.nx : 0, dk = g.nz > 1 ? g.nx * g.ny : 0;
  const float* p = data + (static_cast<int64_t>(c.i) +
                           static_cast<int64_t>(g.nx) * (c.j + static_cast<int64_t>(g.ny) * c.k));
  const float c000 = p[0], c100 = p[di], c010 = p[dj], c110 = p[dj + di];
  const float c001 = p[dk], c101 = p[dk + di], c011 = p[dk + dj], c111 = p[dk + dj + di];
  const float x00 = lerp_value(c000, c100, c.fx), x10 = lerp_value(c010, c110, c.fx);
  const float x01 = lerp_value(c001, c101, c.fx), x11 = lerp_value(c011, c111, c.fx);
  const float y0 = lerp_value(x00, x10, c.fy), y1 = lerp_value(x01, x11, c.fy);
  TrilinearGradient out;
  out.value = lerp_value(y0, y1, c.fz);
  out.gradient.z = g.nz > 1 ? y1 - y0 : 0.0f;
  const float dy0 = x10 - x00, dy1 = x11 - x01;
  out.gradient.y = g.ny > 1 ? lerp_value(dy0, dy1, c.fz) : 0.0f;
  const float dx00 = c100 - c000, dx10 = c110 - c010, dx01 = c101 - c001, dx11 = c111 - c011;
  out.gradient.x =
      g.nx > 1 ? lerp_value(lerp_value(dx00, dx10, c.fy), lerp_value(dx01, dx11, c.fy), c.fz) : 0.0f;
  const float corners[8] = {c000, c100, c010, c110, c001, c101, c011, c111};
  out.lo = out.hi = c000;
  for (int q = 1; q < 8; ++q) {
    out.lo = corners[q] < out.lo ? corners[q] : out.lo;
    out.hi = corners[q] > out.hi ? corners[q] : out.hi;
  }
  return out;
}

// Beyond the grid a sample is the nearest boundary cell's (locate clamps the index): along a
// clamped axis the interpolant does not change, so its gradient there is zero.
SPH_HD Vec3 without_clamped_axes(Vec3 gradient_index, const SdfGridView& g, Vec3 idx) {
  if (!(idx.x >= 0.0f && idx.x <= static_cast<float>(g.nx - 1))) gradient_index.x = 0.0f;
  if (!(idx.y >= 0.0f && idx.y <= static_cast<float>(g.ny - 1))) gradient_index.y = 0.0f;
  if (!(idx.z >= 0.0f && idx.z <= static_cast<float>(g.nz - 1))) gradient_index.z = 0.0f;
  return gradient_index;
}

// The map's correction in one cell: the tensor-product cubic Hermite interpolant of the corners'
// values C_o and gradients G_o (index space, as boundary_map.h stores them; the cross derivatives
// taken as zero),
//     C(f) = sum_o [prod_a phi_{o_a}(f_a)] C_o + sum_o sum_a psi_{o_a}(f_a) [prod_{b != a} phi_{o_b}(f_b)]
//     G_o,a
// with phi_0(t) = 1 - 3t^2 + 2t^3, phi_1 = 1 - phi_0, psi_0(t) = t (1 - t)^2, psi_1(t) = -t^2 (1 - t),
// and the exact gradient of that. It takes the corners' values and gradients at the corners, is
// continuous with its gradient across cells (a face's values and normal slopes depend on that
// face's corners alone), and its gradient is the gradient of its value (local_boundary_share says
// why that matters). hermite_basis gives phi_o, psi_o and their derivatives at t.
SPH_HD void hermite_basis(float t, int o, float& phi, float& dphi, float& psi, float& dpsi) {
  const float t2 = t * t, u = 1.0f - t;
  const float p0 = 1.0f - 3.0f * t2 + 2.0f * t2 * t, dp0 = 6.0f * t2 - 6.0f * t;
  phi = o ? 1.0f - p0 : p0;
  dphi = o ? -dp0 : dp0;
  psi = o ? -t2 * u : t * u * u;
  dpsi = o ? 3.0f * t2 - 2.0f * t : u * u - 2.0f * t * u;
}

struct InterpolatedCorrection {
  float value;
  Vec3 gradient;  // d/d(index)
};

SPH_HD InterpolatedCorrection hermite_correction(const Float4* data, const SdfGridView& g,
                                                 const TrilinearCell& c) {
  const int32_t di = g.nx > 1 ? 1 : 0, dj = g.ny > 1 ? g.nx : 0, dk = g.nz > 1 ? g.nx * g.ny : 0;
  const Float4* p = data + (static_cast<int64_t>(c.i) +
                            static_cast<int64_t>(g.nx) * (c.j + static_cast<int64_t>(g.ny) * c.k));
  InterpolatedCorrection out{0.0f, Vec3{0.0f, 0.0f, 0.0f}};
  for (int o = 0; o < 8; ++o) {
    const int ox = o & 1, oy = (o >> 1) & 1, oz = (o >> 2) & 1;
    const Float4 q = p[ox * di + oy * dj + oz * dk];
    float ax, dax, bx, dbx, ay, day, by, dby, az, daz, bz, dbz;
    hermite_basis(c.fx, ox, ax, dax, bx, dbx);
    hermite_basis(c.fy, oy, ay, day, by, dby);
    hermite_basis(c.fz, oz, az, daz, bz, dbz);
    out.value += ax * ay * az * q.x + bx * ay * az * q.y + ax * by * az * q.z + ax * ay * bz * q.w;
    out.gradient +=
        Vec3{dax * ay * az * q.x + dbx * ay * az * q.y + dax * by * az * q.z + dax * ay * bz * q.w,
             ax * day * az * q.x + bx * day * az * q.y + ax * dby * az * q.z + ax * day * bz * q.w,
             ax * ay * daz * q.x + bx * ay * daz * q.y + ax * by * daz * q.z + ax * ay * dbz * q.w};
  }
  if (g.nx <= 1) out.gradient.x = 0.0f;
  if (g.ny <= 1) out.gradient.y = 0.0f;
  if (g.nz <= 1) out.gradient.z = 0.0f;
  return out;
}

// The form of a map's correction for the solid {phi < level} (boundary_map.h): a distance where the
// level lies below the SDF's surface (a solid collider's map: its solid moved delta into it, the
// particles outside it, where a convex edge's share falls far below the flat share and an added
// share interpolated across the edge went negative), a share elsewhere (a container's map, whose
// particles lie inside the cavity grown by delta; and level 0).
SPH_HD bool map_corrects_distance(float level) { return level < 0.0f; }

// Phi and grad Phi (local frame) of the solid where sigma (phi - level) < 0, at a local point: the
// flat-wall share of the trilinear SDF plus the map's correction for that level (null map: the
// flat-wall share alone).
struct LocalBoundaryShare {
  float share;    // Phi in [0, 1] (up to the correction's error)
  Vec3 gradient;  // grad Phi, 1/m, local frame
};

SPH_HD LocalBoundaryShare local_boundary_share(const SdfGridView& g, const Float4* correction, float sign,
                                               float level, float h, Vec3 local) {
  const Vec3 idx = apply_affine(g.local_to_index, local);
  const TrilinearCell cell = locate(g, local);
  const TrilinearGradient phi = trilinear_with_gradient(g.distance, g, cell);
  // Beyond the grid the SDF grows by the distance to its box (sample_distance); so does phi here,
  // with that distance's gradient.
  float distance = phi.value + cell.outside;
  Vec3 gradient_index = phi.gradient;
  if (cell.outside > 0.0f) {
    gradient_index = without_clamped_axes(gradient_index, g, idx);
    const Vec3 away{idx.x - (static_cast<float>(cell.i) + cell.fx),
                    idx.y - (static_cast<float>(cell.j) + cell.fy),
                    idx.z - (static_cast<float>(cell.k) + cell.fz)};
    const float n = length(away);
    if (n > 0.0f) gradient_index += away * (g.min_voxel_size / n);
  }
  // The map's correction (boundary_map.h): for a solid's map a distance, the offset e by which the
  // flat share must be moved to give the solid's share; for a container's a share added to it.
  const bool as_distance = map_corrects_distance(level);
  float offset = 0.0f, added = 0.0f;
  Vec3 offset_gradient{0.0f, 0.0f, 0.0f}, added_gradient{0.0f, 0.0f, 0.0f};
  // A map node is nonzero only where |phi - level| < h (boundary_map.h); a cell none of whose
  // corners is there interpolates zero, so it is not read. (The test is on the corners rather
  // than on the sample's distance so that the sampled share has no step at the band's edge.)
  if (correction && phi.lo - level < h && phi.hi - level > -h) {
    InterpolatedCorrection d = hermite_correction(correction, g, cell);
    if (cell.outside > 0.0f) d.gradient = without_clamped_axes(d.gradient, g, idx);
    (as_distance ? offset : added) = d.value;
    (as_distance ? offset_gradient : added_gradient) = d.gradient;
  }
  distance = sign * (distance - level + offset);
  LocalBoundaryShare out;
  out.share = spiky_half_space(distance, h) + sign * added;
  // The gradient is that of the sampled share itself (the flat share's slope times the gradient of
  // the trilinear SDF and the offset, plus the added share's Hermite interpolant's), not an
  // interpolation of gradients: the wall's force is then minus the gradient of the energy the
  // density pass sees, so a static wall does no net work on a particle that comes back to where it
  // was. Trilinear interpolation of a map's value and gradient channels separately did not hold
  // that: where the SDF has a kink (a box's edges) the two disagree by up to 10 % of the slope, and
  // a closed tank at rest gained 0.5-0.9 J/s without viscosity (docs/physics.md, "Energy").
  const Vec3 share_gradient =
      (gradient_index + offset_gradient) * (spiky_half_space_slope(distance, h) * sign) +
      added_gradient * sign;
  out.gradient = apply_linear_transposed(g.local_to_index, share_gradient);
  return out;
}

// One collider's share at a world point, at frame fraction s and time tau since the frame's start
// (the pose interpolated as the collider response does; a deforming collider's field advected).
SPH_HD BoundaryShare collider_boundary_share(const BoundaryDensity::Constants& b, const ColliderView& c,
                                             Vec3 world, float s, float tau) {
  RigidTransform pose = c.moving ? interpolate(c.pose_start, c.pose_end, s) : c.pose_start;
  Vec3 local = to_local(pose, world);
  if (c.deforming) local = local - sample_velocity(c.sdf, local) * tau;
  const LocalBoundaryShare l = local_boundary_share(
      c.sdf, c.boundary_map, c.sign, BoundaryDensity::map_level(b, c.sign), b.kernel_radius, local);
  BoundaryShare out;
  out.density = b.density_scale * l.share;
  out.gradient = direction_to_world(pose, l.gradient) * b.density_scale;
  out.velocity_flux = 0.0f;
  if ((c.moving || c.deforming) && out.density > 0.0f) {
    ColliderSample at;
    at.pose = pose;
    at.local = local;
    at.distance = 0.0f;  // collider_velocity reads the pose and the local point only
    out.velocity_flux = dot(collider_velocity(c, at, world), out.gradient);
  }
  return out;
}

// The sum over a scene's colliders. Colliders without a map (boundary_map null) count as flat
// walls of their SDF (their share is still the SDF's half-space value).
SPH_HD BoundaryShare boundary_share(const BoundaryDensity::Constants& b, const ColliderView* colliders,
                                    uint32_t count, Vec3 world, float s, float tau) {
  BoundaryShare sum = no_boundary_share();
  for (uint32_t k = 0; k < count; ++k) {
    const BoundaryShare one = collider_boundary_share(b, colliders[k], world, s, tau);
    sum.density += one.density;
    sum.gradient += one.gradient;
    sum.velocity_flux += one.velocity_flux;
  }
  return sum;
}

// The per-particle record of kArrayBoundaryGradient.
SPH_HD Float4 pack_boundary(const BoundaryShare& s) {
  return make_float4_record(s.gradient, s.velocity_flux);
}
SPH_HD Vec3 boundary_gradient(const Float4& record) { return xyz(record); }

// The wall's share of d rho_i / dt: sum over colliders of (v_i - v_b) . grad rho_b.
SPH_HD float boundary_density_rate(const Float4& record, Vec3 velocity) {
  return dot(velocity, xyz(record)) - record.w;
}

// The wall's pressure acceleration of a particle of pressure p and inverse density inv_rho.
SPH_HD Vec3 boundary_pressure_acceleration(const Float4& record, float pressure, float inv_rho) {
  return xyz(record) * (-pressure * inv_rho * inv_rho);
}

// The force (N) of one particle on one collider: minus the wall's force on the particle
// (momentum is exchanged, not made), for a reduction of loads per collider.
SPH_HD Vec3 boundary_reaction_force(const BoundaryShare& collider_share, float mass, float pressure,
                                    float inv_rho) {
  return collider_share.gradient * (mass * pressure * inv_rho * inv_rho);
}

// The frame fraction and time of an integration stage: the substep's start for symplectic Euler
// and RK4's first stage, its middle for stages 1 and 2, its end for stage 3.
struct StageTime {
  float s, tau;
};
SPH_HD StageTime stage_time(const SubstepTime& t, float fraction) {
  return StageTime{t.s0 + (t.s1 - t.s0) * fraction, t.tau0 + (t.tau1 - t.tau0) * fraction};
}
SPH_HD float rk4_stage_fraction(int stage) { return stage == 0 ? 0.0f : (stage == 3 ? 1.0f : 0.5f); }

}  // namespace sph
