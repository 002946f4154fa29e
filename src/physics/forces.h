// SPDX-License-Identifier: MIT
// The force composer: the acceleration of a particle from its neighbours, as the sum of the
// world's force terms in a fixed order: the pressure force (pressure_force.h) and gravity, then
// each term of the world's ForceTerms list (methods.h: the viscosity method, surface tension).
// Both backends call it; the terms are compile-time types, so a method that is off compiles
// away. Inputs are the packed records written by the density pass: position.w = p_j and
// velocity.w = 1 / rho_j, so a neighbour costs two 16-byte loads and no division.
//
// The pair terms (AccelerationGather::add) and the final combination (finish) are separate so
// that a backend may walk neighbours its own way (the CUDA backend tests a whole run of
// candidates before evaluating pair terms) and still use this arithmetic. Each term keeps its
// own sums and adds into the acceleration in list order, so the floating-point operations are
// those of one hand-written loop in that order.
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "fluid_constants.h"
#include "force_pair.h"
#include "neighbor_walk.h"

namespace sph {

// The arrays the force pass reads, in sorted order. neighbor_counts (the density pass's counts)
// and colour_normals (the colour-field pass) may be null unless a term reads them.
struct ForceInputs {
  const Float4* positions;   // w = p
  const Float4* velocities;  // w = 1 / rho
  const uint32_t* neighbor_counts;
  const Float4* colour_normals;
};

// The terms' sums, one after the other (a tuple that device code can hold).
template <class... Terms>
struct TermSums {};
template <class Term, class... Rest>
struct TermSums<Term, Rest...> {
  typename Term::Sums head;
  TermSums<Rest...> rest;
};

template <class... Terms>
struct TermList;
template <>
struct TermList<> {
  static constexpr bool kReadsNeighborCounts = false;
  static constexpr bool kReadsColourNormals = false;
  SPH_HD static void zero(TermSums<>&) {}
  SPH_HD static void add(const FluidConstants&, const ForceParticle&, const ForcePair&, TermSums<>&) {}
  SPH_HD static void finish(const FluidConstants&, const ForceParticle&, const TermSums<>&, Vec3&) {}
};
template <class Term, class... Rest>
struct TermList<Term, Rest...> {
  using Next = TermList<Rest...>;
  static constexpr bool kReadsNeighborCounts = Term::kReadsNeighborCounts || Next::kReadsNeighborCounts;
  static constexpr bool kReadsColourNormals = Term::kReadsColourNormals || Next::kReadsColourNormals;
  SPH_HD static void zero(TermSums<Term, Rest...>& s) {
    s.head = Term::zero_sums();
    Next::zero(s.rest);
  }
  SPH_HD static void add(const FluidConstants& f, const ForceParticle& i, const ForcePair& j,
                         TermSums<Term, Rest...>& s) {
    Term::add_pair(f, constants_of(f.methods, Tag<Term>{}), i, j, s.head);
    Next::add(f, i, j, s.rest);
  }
  SPH_HD static void finish(const FluidConstants& f, const ForceParticle& i, const TermSums<Term, Rest...>& s,
                            Vec3& a) {
    Term::finish(f, constants_of(f.methods, Tag<Term>{}), i, s.head, a);
    Next::finish(f, i, s.rest, a);
  }
};

// Neighbour j contributes to particle i's forces when within h and not i itself.
SPH_HD bool is_force_neighbor(const FluidConstants& f, float r2, uint32_t i, uint32_t j) {
  return r2 < f.kernel.h2 && j != i;
}

// One particle's gather: construct, add() every force neighbour j (in the order of the
// neighbour walk), then finish(). kPressure: whether the symmetric pressure force is part of it
// (the weakly compressible scheme); DFSPH gathers the other terms alone (its pressure comes
// from its solves, dfsph.h), and its records' position.w holds no pressure.
template <class Terms, bool kPressure = true>
class AccelerationGather;
template <class... Terms, bool kPressure>
class AccelerationGather<ForceTerms<Terms...>, kPressure> {
 public:
  using List = TermList<Terms...>;

  SPH_HD AccelerationGather(const ForceInputs& in, uint32_t i) : in_(in) {
    self_.position = in.positions[i];
    self_.velocity = in.velocities[i];
    self_.x = xyz(self_.position);
    self_.v = xyz(self_.velocity);
    self_.neighbor_count = List::kReadsNeighborCounts ? static_cast<float>(in.neighbor_counts[i]) : 0.0f;
    self_.normal = List::kReadsColourNormals ? in.colour_normals + i : nullptr;
    pressure_ = SymmetricPressure::zero_sums();
    List::zero(sums_);
  }

  SPH_HD Vec3 position() const { return self_.x; }

  // pj = positions[j], d = x_i - x_j, r2 = |d|^2: a force neighbour.
  SPH_HD void add(const FluidConstants& f, uint32_t j, const Float4& pj, Vec3 d, float r2) {
    ForcePair pair;
    pair.position = pj;
    pair.velocity = in_.velocities[j];
    pair.d = d;
    pair.r2 = r2;
    pair.r = SPH_SQRTF(r2);
    pair.pair_neighbors =
        List::kReadsNeighborCounts ? self_.neighbor_count + static_cast<float>(in_.neighbor_counts[j]) : 0.0f;
    pair.normal = List::kReadsColourNormals ? in_.colour_normals + j : nullptr;
    if (kPressure) SymmetricPressure::add_pair(f, self_, pair, pressure_);
    List::add(f, self_, pair, sums_);
  }

  SPH_HD Vec3 finish(const FluidConstants& f) const {
    Vec3 a = kPressure ? SymmetricPressure::acceleration(f, self_, pressure_) + f.gravity : f.gravity;
    List::finish(f, self_, sums_, a);
    return a;
  }

 private:
  ForceInputs in_;
  ForceParticle self_;
  SymmetricPressure::Sums pressure_;
  TermSums<Terms...> sums_;
};

// The whole gather for particle i, walking the neighbour cells in order.
template <class Terms, bool kPressure = true>
SPH_HD Vec3 gather_acceleration(const FluidConstants& f, const GridView& grid, const ForceInputs& in,
                                uint32_t i) {
  AccelerationGather<Terms, kPressure> gather(in, i);
  const Vec3 xi = gather.position();
  for_each_neighbor_candidate(grid, xi, [&](uint32_t j) {
    const Float4 pj = in.positions[j];
    const Vec3 d = xi - xyz(pj);
    const float r2 = length_squared(d);
    if (!is_force_neighbor(f, r2, i, j)) return;
    gather.add(f, j, pj, d, r2);
  });
  return gather.finish(f);
}

}  // namespace sph
