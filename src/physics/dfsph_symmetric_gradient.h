// SPDX-License-Identifier: MIT
// DFSPH's momentum-conserving corrected gradient (experiment, session 17): the Jacobi solves'
// velocity update with pair terms that stay equal and opposite,
//   dv_i = -dt [ sum_j m (k_i + k_j) G_ij + k_i grad rho_b ],  G_ji = -G_ij,
// so the fluid's momentum is conserved to round-off whatever G is, unlike the Bonet-Lok difference
// form of dfsph_gradient_correction.h. Two parts, each optional:
//  - first order: G_ij = Lbar_ij m grad W_ij with Lbar_ij = (L_i + L_j) / 2, L_i the faded inverse of
//    B_i (the same B, fade and matrix as dfsph_gradient_correction.h); symmetric in i, j;
//  - zeroth order: G_ij -= (a_i - a_j) w_ij with w_ij = m W_ij (symmetric) and a per-particle vector
//    a chosen so that sum_j G_ij = Z_i - t_i, t_i = f_i (Z_i + grad rho_b,i / 2) the part of the
//    zeroth-order sum to remove (f_i the fade): (S_i a_i - sum_j w_ij a_j) = t_i, a graph-Laplacian
//    system solved by a few Jacobi sweeps a_i <- (t_i + sum_j w_ij a_j) / S_i (Z is rough, so a few
//    sweeps remove most of it; the part of t with a nonzero sum cannot be removed by an
//    antisymmetric term and stays).
#pragma once

#include <stdint.h>

#include "dfsph_gradient_correction.h"
#include "host_device.h"
#include "vec3.h"

namespace sph {

// A particle's symmetric correction: the faded L (xx, xy, xz, yy, yz, zz) and the vector a.
struct SymmetricCorrection {
  float l[6];
  Vec3 a;
};

// The fade's weight of a moment (rho0 B, Z): 1 in the bulk, 0 where the neighbourhood is truncated.
SPH_HD float correction_fade(const GradientMomentOf<float>& m, float rest_density) {
  const float t = (m.xx + m.yy + m.zz) * (1.0f / (3.0f * rest_density));
  float w = (t - DfsphGradientCorrection::kNone) /
            (DfsphGradientCorrection::kFull - DfsphGradientCorrection::kNone);
  return w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
}

// The faded inverse w B^-1 + (1 - w) I (the identity where det B is not positive).
SPH_HD void faded_inverse(const GradientMomentOf<float>& m, float rest_density, float w, float* l) {
  l[0] = 1.0f, l[1] = 0.0f, l[2] = 0.0f, l[3] = 1.0f, l[4] = 0.0f, l[5] = 1.0f;
  if (w <= 0.0f) return;
  const float s = 1.0f / rest_density;
  const float a = m.xx * s, b = m.xy * s, c = m.xz * s, d = m.yy * s, e = m.yz * s, f = m.zz * s;
  const float A = d * f - e * e, Bc = c * e - b * f, C = b * e - c * d;
  const float det = a * A + b * Bc + c * C;
  if (!(det > 0.0f)) return;
  const float D = a * f - c * c, E = b * c - a * e, F = a * d - b * b;
  const float inv = w / det;
  l[0] += inv * A - w;
  l[1] = inv * Bc;
  l[2] = inv * C;
  l[3] += inv * D - w;
  l[4] = inv * E;
  l[5] += inv * F - w;
}

// (L_i + L_j) / 2 applied to g.
SPH_HD Vec3 averaged_correction(const float* li, const float* lj, Vec3 g) {
  const float xx = 0.5f * (li[0] + lj[0]), xy = 0.5f * (li[1] + lj[1]), xz = 0.5f * (li[2] + lj[2]);
  const float yy = 0.5f * (li[3] + lj[3]), yz = 0.5f * (li[4] + lj[4]), zz = 0.5f * (li[5] + lj[5]);
  return Vec3{xx * g.x + xy * g.y + xz * g.z, xy * g.x + yy * g.y + yz * g.z, xz * g.x + yz * g.y + zz * g.z};
}

}  // namespace sph
