// SPDX-License-Identifier: MIT
// The boundary density's map of an SDF asset for a kernel radius h and an SDF level L (the solid
// {phi < L}; boundary_density.h: L = -sigma delta): per voxel, what the solid's true kernel share
// Phi differs by from the flat-wall share of the SDF, which the sampling adds back,
//     correction(node) = Phi(x) - Phi_flat(x)
// with Phi_flat exactly as local_boundary_share computes it at the node (so a sample at a node
// returns the quadrature's value), and the correction's slopes (d/d index) by central differences
// of those values, which the sampling's cubic Hermite interpolation takes at the voxels: one
// Float4 (correction, slope x, slope y, slope z) per voxel. Zero where |phi - L| >= h: the kernel
// sees one side only there (for an SDF that is a distance), so the voxels to compute are a band
// of 2 h around the surface; the rest of the map is zero. For a solid collider's map (level < 0,
// map_corrects_distance) the value is a distance instead, the offset e with
// Phi_flat(phi - level + e) = Phi at the node, interpolated and differenced the same way: outside a
// solid's convex edge an added share is nearly minus the flat share, a quintic of the distance
// that the interpolation across an edge between samples missed by up to 0.035 and made negative
// (docs/physics.md, "A solid's map corrects the distance"). Both backends call
// boundary_map_correction per band voxel, then, with every value in place, boundary_map_slope:
// the CPU backend on host threads, the CUDA backend one thread per voxel.
//
// The quadrature, in spherical coordinates about the node x: Phi(x) = int over directions w of
// int_0^h W(r) r^2 [x + r w in the solid] dr. The polar axis is the SDF's normal at x, and the
// polar integral is split at mu* = -phi(x) / h, where the rays start to reach a flat surface
// (the integrand's one kink for a plane); each part takes 8-point Gauss-Legendre in mu, and the
// azimuth 8 equal steps, so a flat wall is integrated to about 1e-6 (the azimuth does not
// matter for it and each part is smooth) and curvature to the accuracy the tests state. Along a
// ray the SDF is sampled every half voxel (at least 8 steps over h); the solid's intervals
// between samples are found by linear interpolation of the distance (exact for a plane), and
// the radial integrals over them are closed forms (boundary_integrals.h), so walls thinner than
// the step are where it loses accuracy (docs/physics.md).
#pragma once

#include <stdint.h>

#include "boundary_density.h"
#include "boundary_integrals.h"
#include "float4_types.h"
#include "sdf_sampling.h"

#if defined(__CUDACC__)
#define SPH_CEILF ceilf
#define SPH_COSF cosf
#define SPH_SINF sinf
#else
#include <cmath>
#define SPH_CEILF std::ceil
#define SPH_COSF std::cos
#define SPH_SINF std::sin
#endif

namespace sph {

// 8-point Gauss-Legendre on [-1, 1]: node q (0..7) and its weight.
SPH_HD void gauss_legendre8(int q, float& x, float& w) {
  const int m = q < 4 ? 3 - q : q - 4;  // distance rank from the centre
  float a = 0.0f;
  switch (m) {
    case 0:
      a = 0.1834346424956498f, w = 0.3626837833783620f;
      break;
    case 1:
      a = 0.5255324099163290f, w = 0.3137066458778873f;
      break;
    case 2:
      a = 0.7966664774136267f, w = 0.2223810344533745f;
      break;
    default:
      a = 0.9602898564975363f, w = 0.1012285362903763f;
      break;
  }
  x = q < 4 ? -a : a;
}

constexpr int kBoundaryMapAzimuths = 8;

// What lets a ray skip samples: a bound L on the slope of sample_distance along any local direction
// (SdfSlope, sdf_sampling.h), so that a sample at distance v proves every point within |v| / L of it on the
// same side of the surface. `inverse` is 1 / L (0: no bound known, every sample taken); `slack` (m)
// is taken off |v| first, for the float rounding of the sampled points and values (a skipped sample
// must be one that would have read on that side when computed).
struct RaySkip {
  float inverse = 0.0f;
  float slack = 0.0f;
};

// The radial integrals of W r^2 over the solid's parts of the kBoundaryMapAzimuths rays x + r w[p],
// r in [0, h], marched together: each ray's arithmetic and order are those of one ray alone, and
// the rays' samples of a step are taken together, so that the CPU's compiler can overlap them.
// A step where the skip bound proves, for every ray, which side of the surface it lies on is not
// sampled (the rays of a polar angle see a flat wall alike, so they clear together): an interval
// with both ends outside adds nothing and one with both ends inside adds its whole radial integral,
// neither needing the values; where a ray's sample after such steps lies on the other side, the
// sample before it is taken then. So the sums are the bits that every sample gives.
SPH_HD void integrate_rays(const SdfGridView& g, Vec3 x, const Vec3* w, float h, float level, int steps,
                           float phi0, RaySkip skip, float* out) {
  constexpr int kRays = kBoundaryMapAzimuths;
  float a[kRays], b[kRays];
  // Up to r = known[p] the ray is proved (by a sample) to stay inside the solid (inside[p]) or
  // outside it; every ray up to r = known_all.
  float known[kRays];
  bool inside[kRays];
  const float phi0_size = phi0 < 0.0f ? -phi0 : phi0;
  const float start = phi0_size > skip.slack ? (phi0_size - skip.slack) * skip.inverse : 0.0f;
  for (int p = 0; p < kRays; ++p) a[p] = phi0, out[p] = 0.0f, known[p] = start, inside[p] = phi0 < 0.0f;
  float known_all = start;
  // The step before this one was not sampled: a[] holds values of the rays' proved sides, not r0's.
  bool skipped = false;
  float r0 = 0.0f;
  for (int k = 1; k <= steps; ++k) {
    const float r1 = h * static_cast<float>(k) / static_cast<float>(steps);
    if (r1 < known_all) {
      for (int p = 0; p < kRays; ++p)
        if (inside[p]) out[p] += spiky_radial_volume(r1, h) - spiky_radial_volume(r0, h);
      skipped = true;
      r0 = r1;
      continue;
    }
    for (int p = 0; p < kRays; ++p) b[p] = sample_distance(g, x + w[p] * r1) - level;
    if (skipped) {
      // A ray whose sample lies on the other side needs r0's own value; the others' intervals
      // take none, and a[] holds a value of their side (a sample within the ray's proved reach).
      for (int p = 0; p < kRays; ++p)
        if ((b[p] < 0.0f) != inside[p]) a[p] = sample_distance(g, x + w[p] * r0) - level;
      skipped = false;
    }
    known_all = h;
    for (int p = 0; p < kRays; ++p) {
      float lo = 1.0f, hi = 0.0f;  // the solid's part of [r0, r1], empty unless set
      if (a[p] < 0.0f && b[p] < 0.0f) {
        lo = r0, hi = r1;
      } else if (a[p] < 0.0f) {
        lo = r0, hi = r0 + (r1 - r0) * (a[p] / (a[p] - b[p]));
      } else if (b[p] < 0.0f) {
        lo = r0 + (r1 - r0) * (a[p] / (a[p] - b[p])), hi = r1;
      }
      if (hi > lo) out[p] += spiky_radial_volume(hi, h) - spiky_radial_volume(lo, h);
      a[p] = b[p];
      const float size = b[p] < 0.0f ? -b[p] : b[p];
      const float reach = size > skip.slack ? r1 + (size - skip.slack) * skip.inverse : 0.0f;
      if (reach > known[p]) known[p] = reach, inside[p] = b[p] < 0.0f;
      known_all = known[p] < known_all ? known[p] : known_all;
    }
    r0 = r1;
  }
}

// Radial samples per ray: every half of the smallest voxel, at least 8, at most 64.
SPH_HD int boundary_map_ray_steps(const SdfGridView& g, float h) {
  const float n = 2.0f * h / g.min_voxel_size;
  return n < 8.0f ? 8 : (n > 64.0f ? 64 : static_cast<int>(SPH_CEILF(n)));
}

// The skip of the rays from local point x, a node within h of the surface. The slack is 2^-14 of
// the scales that the float rounding acts on, hundreds of times the rounding itself: the sampled
// point's (ulps of |x| + h, times the slope) and the sampled value's (ulps of the values a cell
// within h of the surface holds: h, a cell's change, the level).
SPH_HD RaySkip ray_skip_at(Vec3 x, float h, float level, SdfSlope slope) {
  RaySkip skip;
  if (!(slope.bound > 0.0f)) return skip;
  const float ax = x.x < 0.0f ? -x.x : x.x, ay = x.y < 0.0f ? -x.y : x.y, az = x.z < 0.0f ? -x.z : x.z;
  const float reach = (ax > ay ? (ax > az ? ax : az) : (ay > az ? ay : az)) + h;
  const float values = 4.0f * h + slope.cell_change + (level < 0.0f ? -level : level);
  skip.inverse = 1.0f / slope.bound;
  skip.slack = 6.103515625e-05f * (slope.bound * reach + values);
  return skip;
}

// The share of the solid {phi < level} at local point x by the quadrature above, phi the SDF
// there less level (a node's own value for the map; sample_distance elsewhere): no map and no
// interpolation, what the map stores at a node and what tests compare the sampling with.
// slope: what lets the rays skip samples (ray_skip_at; none: every sample taken; the same share).
SPH_HD float boundary_quadrature_share(const SdfGridView& g, Vec3 x, float phi, float h, float level,
                                       SdfSlope slope = SdfSlope{}) {
  if (!(phi > -h)) return 1.0f;
  if (!(phi < h)) return 0.0f;
  Vec3 n = sample_normal(g, x);
  if (length_squared(n) == 0.0f) n = Vec3{0.0f, 0.0f, 1.0f};
  // Two tangents completing n to an orthonormal frame.
  const Vec3 helper = (n.x > 0.9f || n.x < -0.9f) ? Vec3{0.0f, 1.0f, 0.0f} : Vec3{1.0f, 0.0f, 0.0f};
  Vec3 t1 = cross(helper, n);
  t1 = t1 * (1.0f / length(t1));
  const Vec3 t2 = cross(n, t1);
  const int steps = boundary_map_ray_steps(g, h);
  const RaySkip skip = ray_skip_at(x, h, level, slope);
  float kink = -phi / h;
  kink = kink < -1.0f ? -1.0f : (kink > 1.0f ? 1.0f : kink);
  float share = 0.0f;
  const float azimuth_weight = 2.0f * kPi / static_cast<float>(kBoundaryMapAzimuths);
  // The azimuths' in-plane directions, once a node rather than once a ray (the same values).
  Vec3 across[kBoundaryMapAzimuths];
  for (int p = 0; p < kBoundaryMapAzimuths; ++p) {
    const float angle = azimuth_weight * (static_cast<float>(p) + 0.5f);
    across[p] = t1 * SPH_COSF(angle) + t2 * SPH_SINF(angle);
  }
  for (int part = 0; part < 2; ++part) {
    const float lo = part == 0 ? -1.0f : kink, hi = part == 0 ? kink : 1.0f;
    if (!(hi > lo)) continue;
    for (int q = 0; q < 8; ++q) {
      float node = 0.0f, weight = 0.0f;
      gauss_legendre8(q, node, weight);
      const float mu = 0.5f * (lo + hi) + 0.5f * (hi - lo) * node;
      const float sin_theta = SPH_SQRTF(1.0f - mu * mu > 0.0f ? 1.0f - mu * mu : 0.0f);
      const float w_mu = 0.5f * (hi - lo) * weight * azimuth_weight;
      Vec3 w[kBoundaryMapAzimuths];
      float radial[kBoundaryMapAzimuths];
      for (int p = 0; p < kBoundaryMapAzimuths; ++p) w[p] = n * mu + across[p] * sin_theta;
      integrate_rays(g, x, w, h, level, steps, phi, skip, radial);
      for (int p = 0; p < kBoundaryMapAzimuths; ++p) share += w_mu * radial[p];
    }
  }
  return share;
}

// The flat share's inverse: the distance D in [-h, h] from a flat wall at which the half space's
// share is q (spiky_half_space decreases from 1 at -h to 0 at h), by bisection in double (the
// map's construction only); q <= 0 gives h and q >= 1 gives -h.
SPH_HD float spiky_half_space_inverse(float q, float h) {
  double lo = -static_cast<double>(h), hi = static_cast<double>(h);
  if (!(q > 0.0f)) return h;
  if (!(q < 1.0f)) return -h;
  for (int k = 0; k < 48; ++k) {
    const double mid = 0.5 * (lo + hi);
    (spiky_half_space<double>(mid, h) > static_cast<double>(q) ? lo : hi) = mid;
  }
  return static_cast<float>(0.5 * (lo + hi));
}

// The correction of voxel (i, j, k) for the solid {phi < level} (index_to_local is the inverse of
// g.local_to_index): for a solid's map (map_corrects_distance) the offset e (m) that makes the flat
// share of the moved distance the quadrature's share, Phi_flat(phi - level + e) = Phi; otherwise
// the share Phi - Phi_flat(phi - level). slope: as for boundary_quadrature_share (the same value).
SPH_HD float boundary_map_correction(const SdfGridView& g, const Affine3x4& index_to_local, int32_t i,
                                     int32_t j, int32_t k, float h, float level, SdfSlope slope) {
  const float phi =
      -level +
      g.distance[static_cast<int64_t>(i) + static_cast<int64_t>(g.nx) * (j + static_cast<int64_t>(g.ny) * k)];
  if (!(phi > -h && phi < h)) return 0.0f;
  const Vec3 x =
      apply_affine(index_to_local, Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)});
  const float share = boundary_quadrature_share(g, x, phi, h, level, slope);
  if (map_corrects_distance(level)) {
    // The inverse's slope grows without bound as the share nears 0 or 1 (one float ulp at 1 moves
    // the distance by 0.03 h), and the quadrature's share carries rounding errors of order 1e-7
    // whatever its size, which the host's and the device's compilations make differently: a share
    // within kShareMargin of 0 or 1 is inverted at the margin, an over- or under-read of at most
    // kShareMargin of a whole wall's share. 1e-5 (the inverse's slope there about 2e3 h) was not
    // enough: a DFSPH paddle driven through a ball parted by 2.5 mm within 10 substeps, on the CPU,
    // when the shares were moved by +-1e-7 before the inversion (as the H200's did, by the same
    // 2.5 mm); at 1e-3 the same perturbation moves the run by 3e-7 m (docs/physics.md).
    constexpr float kShareMargin = 1e-3f;
    const float q =
        share < kShareMargin ? kShareMargin : (share > 1.0f - kShareMargin ? 1.0f - kShareMargin : share);
    return spiky_half_space_inverse(q, h) - phi;
  }
  return share - local_boundary_share(g, nullptr, 1.0f, level, h, x).share;
}

// The slopes (d/d index) the sampling's Hermite interpolation takes at voxel (i, j, k): central
// differences of the map's values (one-sided at the grid's faces). Zero outside the band, where
// the value is zero, so that the interpolant is zero in a cell of such voxels (the sampling does
// not read those). Differences rather than the quadrature's own gradient: at a kink of the SDF
// (a box's edges) the flat share's gradient at a voxel is one-sided, and a correction's gradient
// taken against it made the interpolant lopsided (a box's corners read 1.43-1.56 rho0 by which
// corner; with differences all read alike).
SPH_HD Vec3 boundary_map_slope(const SdfGridView& g, const Float4* map, int32_t i, int32_t j, int32_t k,
                               float h, float level) {
  const int64_t v =
      static_cast<int64_t>(i) + static_cast<int64_t>(g.nx) * (j + static_cast<int64_t>(g.ny) * k);
  const float phi = g.distance[v] - level;
  if (!(phi > -h && phi < h)) return Vec3{0.0f, 0.0f, 0.0f};
  const int32_t n[3] = {g.nx, g.ny, g.nz}, at[3] = {i, j, k};
  const int64_t stride[3] = {1, static_cast<int64_t>(g.nx), static_cast<int64_t>(g.nx) * g.ny};
  float slope[3];
  for (int a = 0; a < 3; ++a) {
    const int32_t lo = at[a] > 0 ? at[a] - 1 : at[a], hi = at[a] < n[a] - 1 ? at[a] + 1 : at[a];
    slope[a] = hi > lo ? (map[v + (hi - at[a]) * stride[a]].x - map[v + (lo - at[a]) * stride[a]].x) /
                             static_cast<float>(hi - lo)
                       : 0.0f;
  }
  return Vec3{slope[0], slope[1], slope[2]};
}

}  // namespace sph
