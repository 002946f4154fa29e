// SPDX-License-Identifier: MIT
// A pack of kLaneCount float lanes for the CPU backend's SIMD passes, made of N parts of a
// register type B: one xsimd::batch<float, avx512f> (N = 1), two batch<float, avx2> (N = 2), or
// sixteen plain floats (the generic target, N = 16). It is the T of the shared pair formulas
// (src/physics/lane_math.h): arithmetic, comparisons into a LaneMask, select, square_root.
//
// Every target packs the same 16 lanes and does the same IEEE operations on each (no FMA: the
// target files are built with -ffp-contract=off; division and square root are correctly rounded
// on every target), and the sums end in one fixed tree (reduce_sum), so all targets compute the
// same bits: an AVX2 and an AVX-512 machine agree, and the generic target is their reference
// (tests/unit/test_simd_passes.cpp checks it).
//
// Tag is a type local to each target's file: every instantiation with it has internal linkage,
// so no inline function compiled for one instruction set can stand in for another's at link time.
#pragma once

#include <cmath>

namespace sph {
namespace simd {

constexpr int kLaneCount = 16;

// The register operations of a part type: Ops<float> here, Ops<xsimd::batch<float, A>> in
// cpu_simd_xsimd.h.
template <class Part>
struct PartOps;
template <>
struct PartOps<float> {
  using Bool = bool;
  static float select(bool c, float a, float b) { return c ? a : b; }
  static float sqrt(float x) { return std::sqrt(x); }
  static float load(const float* p) { return *p; }
  static void store(float part, float* p) { *p = part; }
  static bool both(bool a, bool b) { return a && b; }
  static bool either(bool a, bool b) { return a || b; }
  static bool negate(bool a) { return !a; }
  static bool any(bool a) { return a; }
};

template <class Part, int N, class Tag>
struct LaneMask {
  using Ops = PartOps<Part>;
  typename Ops::Bool part[N];

  friend LaneMask operator&&(const LaneMask& a, const LaneMask& b) {
    LaneMask m;
    for (int k = 0; k < N; ++k) m.part[k] = Ops::both(a.part[k], b.part[k]);
    return m;
  }
  friend LaneMask operator||(const LaneMask& a, const LaneMask& b) {
    LaneMask m;
    for (int k = 0; k < N; ++k) m.part[k] = Ops::either(a.part[k], b.part[k]);
    return m;
  }
  friend LaneMask operator!(const LaneMask& a) {
    LaneMask m;
    for (int k = 0; k < N; ++k) m.part[k] = Ops::negate(a.part[k]);
    return m;
  }
  // Whether any lane holds.
  friend bool any(const LaneMask& m) {
    bool found = false;
    for (int k = 0; k < N; ++k) found = found || Ops::any(m.part[k]);
    return found;
  }
};

template <class Part, int N, class Tag>
struct Lanes {
  using Ops = PartOps<Part>;
  using Mask = LaneMask<Part, N, Tag>;
  static constexpr int kPartWidth = kLaneCount / N;
  Part part[N];

  Lanes() = default;
  // A scalar in every lane (implicit, so that float constants mix with lanes in the formulas).
  Lanes(float s) {  // NOLINT(google-explicit-constructor)
    for (int k = 0; k < N; ++k) part[k] = Part(s);
  }

  static Lanes load(const float* p) {
    Lanes v;
    for (int k = 0; k < N; ++k) v.part[k] = Ops::load(p + k * kPartWidth);
    return v;
  }
  void store(float* p) const {
    for (int k = 0; k < N; ++k) Ops::store(part[k], p + k * kPartWidth);
  }

#define SPH_LANES_BINARY(op)                                        \
  friend Lanes operator op(const Lanes& a, const Lanes& b) {        \
    Lanes v;                                                        \
    for (int k = 0; k < N; ++k) v.part[k] = a.part[k] op b.part[k]; \
    return v;                                                       \
  }
  SPH_LANES_BINARY(+)
  SPH_LANES_BINARY(-)
  SPH_LANES_BINARY(*)
  SPH_LANES_BINARY(/)
#undef SPH_LANES_BINARY
#define SPH_LANES_COMPARE(op)                                       \
  friend Mask operator op(const Lanes& a, const Lanes& b) {         \
    Mask m;                                                         \
    for (int k = 0; k < N; ++k) m.part[k] = a.part[k] op b.part[k]; \
    return m;                                                       \
  }
  SPH_LANES_COMPARE(<)
  SPH_LANES_COMPARE(<=)
  SPH_LANES_COMPARE(>)
  SPH_LANES_COMPARE(>=)
  SPH_LANES_COMPARE(==)
  SPH_LANES_COMPARE(!=)
#undef SPH_LANES_COMPARE

  friend Lanes operator-(const Lanes& a) {
    Lanes v;
    for (int k = 0; k < N; ++k) v.part[k] = -a.part[k];
    return v;
  }
  Lanes& operator+=(const Lanes& b) {
    for (int k = 0; k < N; ++k) part[k] = part[k] + b.part[k];
    return *this;
  }

  // The lane vocabulary of src/physics/lane_math.h, found by argument-dependent lookup.
  friend Lanes select(const Mask& c, const Lanes& a, const Lanes& b) {
    Lanes v;
    for (int k = 0; k < N; ++k) v.part[k] = Ops::select(c.part[k], a.part[k], b.part[k]);
    return v;
  }
  friend Lanes square_root(const Lanes& a) {
    Lanes v;
    for (int k = 0; k < N; ++k) v.part[k] = Ops::sqrt(a.part[k]);
    return v;
  }
};

// The sum of the 16 lanes in one fixed tree, the same on every target: lane k takes lane k + 8,
// then k + 4, k + 2, k + 1.
template <class L>
float reduce_sum(const L& v) {
  float lane[kLaneCount];
  v.store(lane);
  for (int half = kLaneCount / 2; half >= 1; half /= 2)
    for (int k = 0; k < half; ++k) lane[k] = lane[k] + lane[k + half];
  return lane[0];
}

// 0, 1, ..., 15: each lane's place in a run of candidates.
template <class L>
L lane_index() {
  float index[kLaneCount];
  for (int k = 0; k < kLaneCount; ++k) index[k] = static_cast<float>(k);
  return L::load(index);
}

}  // namespace simd
}  // namespace sph
