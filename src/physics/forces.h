// SPDX-License-Identifier: MIT
// The force composer: the acceleration of a particle from its neighbours, as the sum of the
// world's force terms in a fixed order: the pressure force (pressure_force.h) and gravity, then
// each term of the world's ForceTerms list (methods.h: the viscosity method, surface tension).
// Both backends call it; the terms are compile-time types, so a method that is off compiles
// away. Inputs are the packed records written by the density pass: position.w = p_j and
// velocity.w = 1 / rho_j, so a neighbour costs two 16-byte loads and no division.
//
// The pair terms (AccelerationGather::add, TermList::add) and the final combination
// (finish_acceleration) are separate so that a backend may walk neighbours its own way (the
// CUDA backend tests a whole run of candidates before evaluating pair terms; the CPU backend
// evaluates them on 16 SIMD lanes at once, src/cpu/cpu_simd_gathers.h) and still use this
// arithmetic. The pair terms are templates on the value type (float, or a pack of lanes: see
// force_pair.h); finish is scalar. Each term keeps its own sums and adds into the acceleration
// in list order, so the floating-point operations of AccelerationGather are those of one
// hand-written loop in that order.
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

// The terms' sums, one after the other (a tuple that device code can hold), for value type T.
template <class T, class... Terms>
struct TermSums {};
template <class T, class Term, class... Rest>
struct TermSums<T, Term, Rest...> {
  typename Term::template SumsOf<T> head;
  TermSums<T, Rest...> rest;
};

template <class... Terms>
struct TermList;
template <>
struct TermList<> {
  static constexpr bool kReadsNeighborCounts = false;
  static constexpr bool kReadsColourNormals = false;
  template <class T>
  SPH_HD static void zero(TermSums<T>&) {}
  template <class T>
  SPH_HD static void add(const FluidConstants&, const ForceParticleOf<T>&, const ForcePairOf<T>&,
                         TermSums<T>&) {}
  SPH_HD static void finish(const FluidConstants&, const ForceParticle&, const TermSums<float>&, Vec3&) {}
};
template <class Term, class... Rest>
struct TermList<Term, Rest...> {
  using Next = TermList<Rest...>;
  static constexpr bool kReadsNeighborCounts = Term::kReadsNeighborCounts || Next::kReadsNeighborCounts;
  static constexpr bool kReadsColourNormals = Term::kReadsColourNormals || Next::kReadsColourNormals;
  template <class T>
  SPH_HD static void zero(TermSums<T, Term, Rest...>& s) {
    s.head = Term::template zero_sums<T>();
    Next::zero(s.rest);
  }
  template <class T>
  SPH_HD static void add(const FluidConstants& f, const ForceParticleOf<T>& i, const ForcePairOf<T>& j,
                         TermSums<T, Term, Rest...>& s) {
    Term::add_pair(f, constants_of(f.methods, Tag<Term>{}), i, j, s.head);
    Next::add(f, i, j, s.rest);
  }
  SPH_HD static void finish(const FluidConstants& f, const ForceParticle& i,
                            const TermSums<float, Term, Rest...>& s, Vec3& a) {
    Term::finish(f, constants_of(f.methods, Tag<Term>{}), i, s.head, a);
    Next::finish(f, i, s.rest, a);
  }
};

// Neighbour j contributes to particle i's forces when within h and not i itself.
SPH_HD bool is_force_neighbor(const FluidConstants& f, float r2, uint32_t i, uint32_t j) {
  return r2 < f.kernel.h2 && j != i;
}

// Particle i as the force terms see it, read from the records of the density pass.
template <class List>
SPH_HD ForceParticle force_particle(const ForceInputs& in, uint32_t i) {
  ForceParticle p;
  const Float4 position = in.positions[i];
  const Float4 velocity = in.velocities[i];
  p.x = xyz(position);
  p.pressure = position.w;
  p.v = xyz(velocity);
  p.inv_density = velocity.w;
  p.neighbor_count = List::kReadsNeighborCounts ? static_cast<float>(in.neighbor_counts[i]) : 0.0f;
  const Float4 normal = List::kReadsColourNormals ? in.colour_normals[i] : Float4{0.0f, 0.0f, 0.0f, 0.0f};
  p.normal = xyz(normal);
  p.normal_length = normal.w;
  return p;
}

// The acceleration from the summed terms: the pressure acceleration plus gravity, then each
// term's part in list order.
// kPressure: whether the symmetric pressure force is part of it (see AccelerationGather).
template <class List, class TermSumsType, bool kPressure = true>
SPH_HD Vec3 finish_acceleration(const FluidConstants& f, const ForceParticle& i,
                                const SymmetricPressure::Sums& pressure, const TermSumsType& sums) {
  Vec3 a = kPressure ? SymmetricPressure::acceleration(f, i, pressure) + f.gravity : f.gravity;
  List::finish(f, i, sums, a);
  return a;
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

  SPH_HD AccelerationGather(const ForceInputs& in, uint32_t i) : in_(in), self_(force_particle<List>(in, i)) {
    pressure_ = SymmetricPressure::zero_sums();
    List::zero(sums_);
  }

  SPH_HD Vec3 position() const { return self_.x; }

  // pj = positions[j], d = x_i - x_j, r2 = |d|^2: a force neighbour.
  SPH_HD void add(const FluidConstants& f, uint32_t j, const Float4& pj, Vec3 d, float r2) {
    const Float4 vj = in_.velocities[j];
    ForcePair pair;
    pair.pressure = pj.w;
    pair.v = xyz(vj);
    pair.inv_density = vj.w;
    pair.d = d;
    pair.r2 = r2;
    pair.r = SPH_SQRTF(r2);
    pair.pair_neighbors =
        List::kReadsNeighborCounts ? self_.neighbor_count + static_cast<float>(in_.neighbor_counts[j]) : 0.0f;
    const Float4 normal = List::kReadsColourNormals ? in_.colour_normals[j] : Float4{0.0f, 0.0f, 0.0f, 0.0f};
    pair.normal = xyz(normal);
    pair.normal_length = normal.w;
    pair.neighbor = true;
    if (kPressure) SymmetricPressure::add_pair(f, self_, pair, pressure_);
    List::add(f, self_, pair, sums_);
  }

  // Calls combine(sums) on the symmetric pressure's sums, then on the terms' (a TermSums), so
  // that a backend splitting one particle's neighbours over several lanes can add the lanes'
  // partial sums before finish() (the CUDA backend's lane groups, cuda/force_gather.cuh).
  template <class Combine>
  SPH_HD void combine_sums(Combine&& combine) {
    combine(pressure_);
    combine(sums_);
  }

  SPH_HD Vec3 finish(const FluidConstants& f) const {
    return finish_acceleration<List, TermSums<float, Terms...>, kPressure>(f, self_, pressure_, sums_);
  }

 private:
  ForceInputs in_;
  ForceParticle self_;
  SymmetricPressure::Sums pressure_;
  TermSums<float, Terms...> sums_;
};

// The whole gather for particle i, walking the neighbour cells in order. (CUDA DFSPH's force pass
// runs the same body over its solves' walk, with the density solve's warm start beside it:
// cuda/dfsph_solver.cu.)
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
