// SPDX-License-Identifier: MIT
// DFSPH's corrected pressure gradient (sph_dfsph_params.flags SPH_DFSPH_CORRECTED_GRADIENT): the
// kernel-gradient correction of Bonet & Lok (1999) in the Jacobi solves' velocity update.
//
// The symmetric update -dt sum_j m (k_i + k_j) grad W_ij (dfsph_passes.h) is, for a pressure that
// varies linearly, k_j = k_i + grad k . (x_j - x_i),
//   -dt [ rho0 B_i grad k + 2 k_i Z_i ],  B_i = sum_j V_j grad W_ij (x) (x_j - x_i),  Z_i = sum_j m grad
//   W_ij,
// V_j = m / rho0: exact (B = I, Z = 0) only on the lattice the kernel is scaled on. On the packing a
// resting tank settles into, B_yy is 1.02-1.03 and the zeroth-order force 2 k_i Z_i differs from
// particle to particle by several percent of g, so each particle's pressure, the multiplier that
// balances its weight through that operator, scatters by 6-8 % about rho0 g d, and a slice of 60
// particles reads its mean to about 1 % (docs/validation.md, "DFSPH: hydrostatic tank").
//
// The corrected update is
//   -dt L_i [ sum_j m (k_i + k_j) grad W_ij - 2 (1 - beta) k_i Z_i ],  L_i = B_i^-1,
// that is L_i applied to the difference form sum_j m (k_j - k_i) grad W_ij (exactly rho0 grad k for
// a linear k on any packing: first-order consistent) plus a share beta = kKeptZeroth of the
// zeroth-order term. That share is kept because the difference form alone exerts no force for a
// uniform pressure, so nothing holds the packing: measured, the tank then never settles (v_rms
// 0.12-0.18 m/s against 0.03). beta = 0.2 keeps it at rest (0.035 m/s) while the particles' scatter
// falls to 2-3 %; 0.5 gives 3.5-5 %. The removed share does work: the DFSPH closed box gains 4.4 %
// energy at 0.2 on the CPU in session 16 (none at 0.4 and above), and in session 26 -0.08 % on the
// CPU but +162 % on an H200: a draw of an unstable case (docs/physics.md).
//
// Where the neighbourhood is truncated (a free surface, the first layers at a wall) B loses rank
// and removing the zeroth-order term would let a particle's own pressure pull it into the fluid
// (the Jacobi step's diagonal turns negative: the tank went non-finite within 5 substeps with the
// fade below), so the correction fades out with the mean of B's diagonal, t = trace(B) / 3 (1 in
// the bulk, about 0.5 at a flat surface): the full correction at t >= kFull, none at t <= kNone,
// linear in between. The walls' share (dfsph_boundary.h, place 3) is not multiplied by L_i, but
// keeps the same share of itself as the fluid's zeroth-order term (corrected_wall_share, below).
// The loads (collider_loads.h) still count it whole: where w > 0 they over-count the walls'
// reaction by (1 - beta) w k_i grad rho_b (not measured apart; docs/physics.md).
//
// The price: the pair terms are no longer antisymmetric (L_i != L_j, and the zeroth-order removal
// is one-sided), so the fluid's momentum is not conserved to round-off (docs/physics.md measures
// the drift). B and Z are gathered in the velocity update's own walk (no array; seven products
// and nine sums more per pair), and the factor alpha is the uncorrected one.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "vec3.h"

namespace sph {

// The correction's constants (see above): the fade, full at trace(B)/3 >= kFull, none at <= kNone
// (measured: a fade from 0.90 to 0.97 left the tank churning at 0.18 m/s without the kept share),
// and the share beta of the zeroth-order term kept.
struct DfsphGradientCorrection {
  static constexpr float kFull = 0.99f;
  static constexpr float kNone = 0.94f;
  static constexpr float kKeptZeroth = 0.2f;
};

// Per particle: -sum_j (m grad W_ij) (x) d_ij (d_ij = x_i - x_j), which is rho0 B_i, and the
// zeroth-order sum sum_j m grad W_ij. T is float or a pack of lanes.
template <class T>
struct GradientMomentOf {
  T xx, xy, xz, yy, yz, zz;
  Vec3Of<T> zeroth;
};
template <class T>
SPH_HD GradientMomentOf<T> zero_gradient_moment(T zero) {
  return GradientMomentOf<T>{zero, zero, zero, zero, zero, zero, Vec3Of<T>{zero, zero, zero}};
}
// g = m grad W_ij (0 for a lane that is not a neighbour), d = x_i - x_j.
template <class T>
SPH_HD void add_gradient_moment(GradientMomentOf<T>& b, Vec3Of<T> g, Vec3Of<T> d) {
  b.xx = b.xx - g.x * d.x;
  b.xy = b.xy - g.x * d.y;
  b.xz = b.xz - g.x * d.z;
  b.yy = b.yy - g.y * d.y;
  b.yz = b.yz - g.y * d.z;
  b.zz = b.zz - g.z * d.z;
  b.zeroth += g;
}

// The moment a velocity update gathers: GradientMomentOf<T> with the correction (kCorrected),
// an empty struct without it, so that the plain update's walk carries no moment at all.
struct NoGradientMoment {};
template <class T, bool kCorrected>
struct GradientMomentIfOf {
  using type = NoGradientMoment;
};
template <class T>
struct GradientMomentIfOf<T, true> {
  using type = GradientMomentOf<T>;
};
template <class T, bool kCorrected>
using GradientMomentIf = typename GradientMomentIfOf<T, kCorrected>::type;
template <bool kCorrected, class T>
SPH_HD GradientMomentIf<T, kCorrected> gradient_moment_if(T zero) {
  if constexpr (kCorrected)
    return zero_gradient_moment(zero);
  else
    return NoGradientMoment{};
}

// The corrected sum and the fade's weight w it was blended with (0: the uncorrected sum).
struct CorrectedPressureSum {
  Vec3 sum;
  float weight;
};

// The corrected sum from sum = sum_j m (k_i + k_j) grad W_ij and the moment (rho0 B_i, Z_i): the sum
// the velocity update multiplies by -dt, before the walls' share. Blended with the uncorrected sum by
// the fade's weight w; uncorrected (w = 0) where det B is not positive.
SPH_HD CorrectedPressureSum corrected_pressure_sum(Vec3 sum, const GradientMomentOf<float>& m, float ki,
                                                   float rest_density) {
  const float s = 1.0f / rest_density;
  const float a = m.xx * s, b = m.xy * s, c = m.xz * s, d = m.yy * s, e = m.yz * s, f = m.zz * s;
  const float t = (a + d + f) * (1.0f / 3.0f);
  float w = (t - DfsphGradientCorrection::kNone) /
            (DfsphGradientCorrection::kFull - DfsphGradientCorrection::kNone);
  w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
  if (w <= 0.0f) return CorrectedPressureSum{sum, 0.0f};
  // The adjugate of the symmetric B = [[a b c] [b d e] [c e f]].
  const float A = d * f - e * e, Bc = c * e - b * f, C = b * e - c * d;
  const float det = a * A + b * Bc + c * C;
  if (!(det > 0.0f)) return CorrectedPressureSum{sum, 0.0f};
  const float D = a * f - c * c, E = b * c - a * e, F = a * d - b * b;
  const float inv = 1.0f / det;
  // The difference form's sum plus the kept share of the zeroth-order term.
  const Vec3 r = sum - m.zeroth * (2.0f * (1.0f - DfsphGradientCorrection::kKeptZeroth) * ki);
  const Vec3 lr{inv * (A * r.x + Bc * r.y + C * r.z), inv * (Bc * r.x + D * r.y + E * r.z),
                inv * (C * r.x + E * r.y + F * r.z)};
  return CorrectedPressureSum{sum + (lr - sum) * w, w};
}

// The share of the walls' term k_i grad rho_b that the corrected update keeps: the walls' share is
// the zeroth-order term of the part of the neighbourhood the walls stand for (at uniform pressure it
// balances the fluid's 2 k_i Z_i at a calibrated wall), so it keeps the same share beta as the
// fluid's, blended by the same weight. Kept whole, it pushed the layers h or so from a wall (where
// the fade lets the correction in) away from it by 2 (1 - beta) k_i |Z_i| w: a tank started with its
// first layer step / 2 from the walls went non-finite in its first frame (session 26).
SPH_HD float corrected_wall_share(float weight) {
  return 1.0f - weight * (1.0f - DfsphGradientCorrection::kKeptZeroth);
}

}  // namespace sph
