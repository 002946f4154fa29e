// The boundary density's map of an SDF asset for a kernel radius h and an SDF level L (the solid
// {phi < L}; boundary_density.h: L = -sigma delta): per voxel, what the solid's true kernel share
// Phi and its gradient differ by from the flat-wall share of the SDF, which the sampling adds back:
//     correction(node) = (Phi(x) - Phi_flat, grad Phi(x) - grad Phi_flat)
// with Phi_flat and its gradient exactly as local_boundary_share computes them at the node (so a
// sample at a node returns the quadrature's values). Zero where |phi - L| >= h: the kernel sees one
// side only there (for an SDF that is a distance), so the voxels to compute are a band of 2 h
// around the surface; the rest of the map is zero. Both backends call boundary_map_correction
// per band voxel: the CPU backend on host threads, the CUDA backend one thread per voxel.
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

// The radial integrals of W r^2 and -W' r^2 over the solid's part of the ray x + r w, r in [0, h].
struct RayIntegral {
  float volume;    // sum of spiky_radial_volume differences
  float gradient;  // sum of spiky_radial_gradient differences
};

SPH_HD RayIntegral integrate_ray(const SdfGridView& g, Vec3 x, Vec3 w, float h, float level, int steps,
                                 float phi0) {
  RayIntegral out{0.0f, 0.0f};
  float r0 = 0.0f, a = phi0;
  for (int k = 1; k <= steps; ++k) {
    const float r1 = h * static_cast<float>(k) / static_cast<float>(steps);
    const float b = sample_distance(g, x + w * r1) - level;
    float lo = 1.0f, hi = 0.0f;  // the solid's part of [r0, r1], empty unless set
    if (a < 0.0f && b < 0.0f) {
      lo = r0, hi = r1;
    } else if (a < 0.0f) {
      lo = r0, hi = r0 + (r1 - r0) * (a / (a - b));
    } else if (b < 0.0f) {
      lo = r0 + (r1 - r0) * (a / (a - b)), hi = r1;
    }
    if (hi > lo) {
      out.volume += spiky_radial_volume(hi, h) - spiky_radial_volume(lo, h);
      out.gradient += spiky_radial_gradient(hi, h) - spiky_radial_gradient(lo, h);
    }
    r0 = r1, a = b;
  }
  return out;
}

// Radial samples per ray: every half of the smallest voxel, at least 8, at most 64.
SPH_HD int boundary_map_ray_steps(const SdfGridView& g, float h) {
  const float n = 2.0f * h / g.min_voxel_size;
  return n < 8.0f ? 8 : (n > 64.0f ? 64 : static_cast<int>(SPH_CEILF(n)));
}

// The correction of voxel (i, j, k) for the solid {phi < level}; index_to_local is the inverse of
// g.local_to_index.
SPH_HD Float4 boundary_map_correction(const SdfGridView& g, const Affine3x4& index_to_local, int32_t i,
                                      int32_t j, int32_t k, float h, float level) {
  const float phi =
      -level +
      g.distance[static_cast<int64_t>(i) + static_cast<int64_t>(g.nx) * (j + static_cast<int64_t>(g.ny) * k)];
  if (!(phi > -h && phi < h)) return Float4{0.0f, 0.0f, 0.0f, 0.0f};
  const Vec3 x =
      apply_affine(index_to_local, Vec3{static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)});
  Vec3 n = sample_normal(g, x);
  if (length_squared(n) == 0.0f) n = Vec3{0.0f, 0.0f, 1.0f};
  // Two tangents completing n to an orthonormal frame.
  const Vec3 helper = (n.x > 0.9f || n.x < -0.9f) ? Vec3{0.0f, 1.0f, 0.0f} : Vec3{1.0f, 0.0f, 0.0f};
  Vec3 t1 = cross(helper, n);
  t1 = t1 * (1.0f / length(t1));
  const Vec3 t2 = cross(n, t1);
  const int steps = boundary_map_ray_steps(g, h);
  float kink = -phi / h;
  kink = kink < -1.0f ? -1.0f : (kink > 1.0f ? 1.0f : kink);
  float share = 0.0f;
  Vec3 gradient{0.0f, 0.0f, 0.0f};
  const float azimuth_weight = 2.0f * kPi / static_cast<float>(kBoundaryMapAzimuths);
  for (int part = 0; part < 2; ++part) {
    const float lo = part == 0 ? -1.0f : kink, hi = part == 0 ? kink : 1.0f;
    if (!(hi > lo)) continue;
    for (int q = 0; q < 8; ++q) {
      float node = 0.0f, weight = 0.0f;
      gauss_legendre8(q, node, weight);
      const float mu = 0.5f * (lo + hi) + 0.5f * (hi - lo) * node;
      const float sin_theta = SPH_SQRTF(1.0f - mu * mu > 0.0f ? 1.0f - mu * mu : 0.0f);
      const float w_mu = 0.5f * (hi - lo) * weight * azimuth_weight;
      for (int p = 0; p < kBoundaryMapAzimuths; ++p) {
        const float angle = azimuth_weight * (static_cast<float>(p) + 0.5f);
        const Vec3 w = n * mu + (t1 * SPH_COSF(angle) + t2 * SPH_SINF(angle)) * sin_theta;
        const RayIntegral ray = integrate_ray(g, x, w, h, level, steps, phi);
        share += w_mu * ray.volume;
        gradient += w * (w_mu * ray.gradient);
      }
    }
  }
  const LocalBoundaryShare flat = local_boundary_share(g, nullptr, 1.0f, level, h, x);
  const Vec3 dg = gradient - flat.gradient;
  return Float4{share - flat.share, dg.x, dg.y, dg.z};
}

}  // namespace sph
