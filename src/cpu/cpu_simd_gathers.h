// SPDX-License-Identifier: MIT
// The SIMD neighbour gathers, written once over a lane pack L (cpu_simd_lanes.h) and
// instantiated by each target's file (cpu_simd_target_*.cpp) into its SimdPasses table.
//
// The walk is the scalar one's (neighbor_walk.h: nine rows of three cells, each a contiguous run
// of sorted particles), taken 16 candidates at a time: a run's candidates base .. base + 15 fill
// lanes 0 .. 15 from the columns (cpu_neighbor_columns.h), the distance test is a mask, and the
// pair terms of src/physics run on all 16 lanes, each lane adding only where its candidate is a
// neighbour (select, ForcePairOf::only). A run of 16 with no neighbour costs only the test. Lane
// k sums the candidates at k, k + 16, ... of each run, in walk order; the 16 lane sums are then
// combined in reduce_sum's fixed tree. The terms are those of the scalar gathers; only the order
// of their sums differs, the same on every target.
#pragma once

#include <stdint.h>
#include <string.h>

#include <type_traits>

#include "../physics/density.h"
#include "../physics/density_diffusion.h"
#include "../physics/density_normalization.h"
#include "../physics/dfsph_passes.h"
#include "../physics/forces.h"
#include "../physics/surface_tension.h"
#include "cpu_simd_lanes.h"
#include "cpu_simd_passes.h"

// The gathers inline everything they call (the walk, the pair terms, the lane operations):
// left to the inliner's limits, the pair terms were calls that passed kilobyte structs of lanes
// through memory.
#define SPH_SIMD_GATHER __attribute__((flatten))

namespace sph {
namespace simd {

static_assert(kLanePadding >= static_cast<size_t>(kLaneCount), "a run's load may start at the last particle");

template <class L>
Vec3Of<L> broadcast(Vec3 v) {
  return Vec3Of<L>{L(v.x), L(v.y), L(v.z)};
}

template <class L>
Vec3Of<L> load3(const float* x, const float* y, const float* z, uint32_t base) {
  return Vec3Of<L>{L::load(x + base), L::load(y + base), L::load(z + base)};
}

// Calls visit(base, valid) for each run of up to 16 candidates around xi, in walk order: lane k
// is candidate base + k, and `valid` holds the lanes inside the run, less particle `self` when
// exclude_self (the density and force sums leave i out; eq. 31 keeps it).
template <class L, class Visit>
void for_each_candidate_run(const GridView& grid, Vec3 xi, uint32_t self, bool exclude_self, Visit&& visit) {
  const L index = lane_index<L>();
  for_each_neighbor_range(grid, xi, [&](uint32_t begin, uint32_t end) {
    for (uint32_t base = begin; base < end; base += kLaneCount) {
      const uint32_t left = end - base;
      typename L::Mask valid = index < L(static_cast<float>(left < kLaneCount ? left : kLaneCount));
      if (exclude_self && self - base < static_cast<uint32_t>(kLaneCount))
        valid = valid && index != L(static_cast<float>(self - base));
      visit(base, valid);
    }
  });
}

template <class L>
Vec3 reduce_vec3(const Vec3Of<L>& v) {
  return Vec3{reduce_sum(v.x), reduce_sum(v.y), reduce_sum(v.z)};
}

// A term's sums of 16 lanes reduced to one: its SumsOf<T> holds T values only (Vec3Of<T>
// members), so SumsOf<L> is SumsOf<float>'s values, each widened to a lane pack, in order.
template <class Sums, class LaneSums, class L>
Sums reduce_term_sums(const LaneSums& in) {
  constexpr size_t kValues = sizeof(Sums) / sizeof(float);
  static_assert(sizeof(LaneSums) == kValues * sizeof(L), "a term's SumsOf<T> must hold T values only");
  static_assert(std::is_trivially_copyable<LaneSums>::value && std::is_trivially_copyable<Sums>::value, "");
  L lanes[kValues];
  memcpy(static_cast<void*>(lanes), &in, sizeof in);
  float values[kValues];
  for (size_t k = 0; k < kValues; ++k) values[k] = reduce_sum(lanes[k]);
  Sums out;
  memcpy(&out, values, sizeof out);
  return out;
}

template <class L>
void reduce_term_list(const TermSums<L>&, TermSums<float>&) {}
template <class L, class Term, class... Rest>
void reduce_term_list(const TermSums<L, Term, Rest...>& in, TermSums<float, Term, Rest...>& out) {
  out.head = reduce_term_sums<typename Term::Sums, typename Term::template SumsOf<L>, L>(in.head);
  reduce_term_list(in.rest, out.rest);
}

template <class L>
SPH_SIMD_GATHER DensitySample density(const FluidBase& f, const GridView& grid, const NeighborColumns& c,
                                      uint32_t i) {
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const L h2(f.kernel.h2), zero(0.0f), one(1.0f);
  L sum(0.0f), count(0.0f);
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const L r2 = length_squared(x - load3<L>(c.x, c.y, c.z, base));
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    sum += select(neighbor, density_pair_term(f, r2), zero);
    count += select(neighbor, one, zero);
  });
  return DensitySample{f.particle_mass * (f.density_self_weight + reduce_sum(sum)),
                       static_cast<uint32_t>(reduce_sum(count))};
}

template <class L>
SPH_SIMD_GATHER float normalized_density(const FluidBase& f, const GridView& grid, const NeighborColumns& c,
                                         uint32_t i) {
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const L h2(f.kernel.h2), zero(0.0f);
  L mass(0.0f), volume(0.0f);
  for_each_candidate_run<L>(grid, xi, i, false, [&](uint32_t base, const typename L::Mask& valid) {
    const L r2 = length_squared(x - load3<L>(c.x, c.y, c.z, base));
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    const NormalizedDensityPair<L> term = normalized_density_pair_term(f, r2, L::load(c.inv_density + base));
    mass += select(neighbor, term.mass, zero);
    volume += select(neighbor, term.volume, zero);
  });
  return normalized_density_from_sums(f, reduce_sum(mass), reduce_sum(volume));
}

template <class L>
SPH_SIMD_GATHER float density_diffusion(const FluidConstants& f, const GridView& grid,
                                        const NeighborColumns& c, uint32_t i) {
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const L h2(f.kernel.h2), zero(0.0f), one(1.0f), rho_i(1.0f / c.inv_density[i]);
  L rate(0.0f);
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const Vec3Of<L> x_ji = load3<L>(c.x, c.y, c.z, base) - x;
    const L r2 = length_squared(x_ji);
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    const L inv_rho_j = L::load(c.inv_density + base);
    const L term = density_diffusion_pair_term(f, f.methods.density_diffusion, x_ji, square_root(r2),
                                               one / inv_rho_j - rho_i, inv_rho_j);
    rate += select(neighbor, term, zero);
  });
  return reduce_sum(rate);
}

template <class L>
SPH_SIMD_GATHER Float4 colour_normal(const FluidBase& f, const GridView& grid, const NeighborColumns& c,
                                     uint32_t i) {
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const L h2(f.kernel.h2), zero(0.0f);
  const Vec3Of<L> zero3{zero, zero, zero};
  Vec3Of<L> n = zero3;
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const Vec3Of<L> d = x - load3<L>(c.x, c.y, c.z, base);
    const L r2 = length_squared(d);
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    n += select(neighbor, colour_normal_pair_term(f, d, r2), zero3);
  });
  const Vec3 normal = reduce_vec3(n) * f.particle_mass;
  return make_float4_record(normal, length(normal));
}

// DFSPH's density and factor (gather_density_and_factor of dfsph_passes.h).
template <class L>
SPH_SIMD_GATHER DfsphDensitySample dfsph_density_and_factor(const FluidBase& f, const GridView& grid,
                                                            const NeighborColumns& c,
                                                            const BoundaryShare& wall, uint32_t i) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const L h2(f.kernel.h2), zero(0.0f), one(1.0f);
  const Vec3Of<L> zero3{zero, zero, zero};
  L kernel(0.0f), squares(0.0f), count(0.0f);
  Vec3Of<L> gradient = zero3;
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const Vec3Of<L> d = x - load3<L>(c.x, c.y, c.z, base);
    const L r2 = length_squared(d);
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    const DfsphFactorTermsOf<L> t = dfsph_factor_pair_terms(f, mk, d, r2);
    kernel += select(neighbor, t.kernel, zero);
    gradient += select(neighbor, t.gradient, zero3);
    squares += select(neighbor, t.square, zero);
    count += select(neighbor, one, zero);
  });
  return sph::dfsph_density_and_factor(f, reduce_sum(kernel), static_cast<uint32_t>(reduce_sum(count)),
                                       reduce_vec3(gradient), reduce_sum(squares), wall);
}

// DFSPH's D rho_i / Dt (density_rate) over the velocities of the columns vx, vy, vz.
template <class L>
SPH_SIMD_GATHER float dfsph_density_rate(const FluidBase& f, const GridView& grid, const NeighborColumns& c,
                                         const DfsphWalls& walls, uint32_t i) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3 vi{c.vx[i], c.vy[i], c.vz[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const Vec3Of<L> v = broadcast<L>(vi);
  const L h2(f.kernel.h2), zero(0.0f);
  L rate(0.0f);
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const Vec3Of<L> d = x - load3<L>(c.x, c.y, c.z, base);
    const L r2 = length_squared(d);
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    const Vec3Of<L> v_ij = v - load3<L>(c.vx, c.vy, c.vz, base);
    rate += select(neighbor, density_rate_pair_term(mk, d, r2, v_ij), zero);
  });
  return sph::dfsph_density_rate(reduce_sum(rate), walls, i, vi);
}

// DFSPH's velocity change from the pressures k (a column: padded): pressure_velocity_change<kCorrected>'s
// SIMD twin (with kCorrected the corrected gradient: B_i and the zeroth-order sum gathered in the
// same walk). Each keeps its scalar twin's terms: the plain one
// selects the pair term, the corrected one the gradient before its product.
template <class L, bool kCorrected>
SPH_SIMD_GATHER Vec3 dfsph_velocity_change(const FluidBase& f, const GridView& grid, const NeighborColumns& c,
                                           const float* k, const DfsphWalls& walls, uint32_t i, float dt) {
  const KernelCoefficients mk = mass_gradient_kernel(f);
  const Vec3 xi{c.x[i], c.y[i], c.z[i]};
  const Vec3Of<L> x = broadcast<L>(xi);
  const float ki = k[i];
  const L h2(f.kernel.h2), zero(0.0f), k_i(ki);
  const Vec3Of<L> zero3{zero, zero, zero};
  Vec3Of<L> sum = zero3;
  // B_i and the zeroth-order sum: an empty struct without kCorrected.
  GradientMomentIf<L, kCorrected> moment = gradient_moment_if<kCorrected>(zero);
  for_each_candidate_run<L>(grid, xi, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    const Vec3Of<L> d = x - load3<L>(c.x, c.y, c.z, base);
    const L r2 = length_squared(d);
    const typename L::Mask neighbor = valid && r2 < h2;
    if (!any(neighbor)) return;
    const L k_ij = k_i + L::load(k + base);
    if constexpr (kCorrected) {
      const Vec3Of<L> g = select(neighbor, spiky_gradient(mk, d, square_root(r2)), zero3);
      sum += g * k_ij;
      add_gradient_moment(moment, g, d);
    } else {
      sum += select(neighbor, pressure_velocity_pair_term(mk, d, r2, k_ij), zero3);
    }
  });
  if constexpr (kCorrected) {
    const GradientMomentOf<float> m{reduce_sum(moment.xx),     reduce_sum(moment.xy), reduce_sum(moment.xz),
                                    reduce_sum(moment.yy),     reduce_sum(moment.yz), reduce_sum(moment.zz),
                                    reduce_vec3(moment.zeroth)};
    return sph::dfsph_corrected_velocity_change(f, reduce_vec3(sum), m, walls, i, ki, dt);
  } else {
    return sph::dfsph_velocity_change(reduce_vec3(sum), walls, i, ki, dt);
  }
}

// Particle i as the force terms see it (force_particle in forces.h), from the columns.
template <class List>
ForceParticle force_particle_from_columns(const NeighborColumns& c, uint32_t i) {
  ForceParticle p;
  p.x = Vec3{c.x[i], c.y[i], c.z[i]};
  p.pressure = c.pressure[i];
  p.v = Vec3{c.vx[i], c.vy[i], c.vz[i]};
  p.inv_density = c.inv_density[i];
  p.neighbor_count = List::kReadsNeighborCounts ? c.neighbor_count[i] : 0.0f;
  p.normal =
      List::kReadsColourNormals ? Vec3{c.normal_x[i], c.normal_y[i], c.normal_z[i]} : Vec3{0.0f, 0.0f, 0.0f};
  p.normal_length = List::kReadsColourNormals ? c.normal_length[i] : 0.0f;
  return p;
}

// kPressure: with the symmetric pressure force (the weakly compressible scheme), or without it
// (DFSPH's non-pressure accelerations: its pressure comes from its solves, and the pressure
// column then holds their k, which this gather does not read).
template <class L, bool kPressure, class... Terms>
SPH_SIMD_GATHER Vec3 acceleration(const FluidConstants& f, const GridView& grid, const NeighborColumns& c,
                                  uint32_t i) {
  using List = TermList<Terms...>;
  const ForceParticle self = force_particle_from_columns<List>(c, i);
  ForceParticleOf<L> lanes_self;
  lanes_self.x = broadcast<L>(self.x);
  lanes_self.pressure = L(self.pressure);
  lanes_self.v = broadcast<L>(self.v);
  lanes_self.inv_density = L(self.inv_density);
  lanes_self.neighbor_count = L(self.neighbor_count);
  lanes_self.normal = broadcast<L>(self.normal);
  lanes_self.normal_length = L(self.normal_length);
  const L h2(f.kernel.h2), zero(0.0f);
  SymmetricPressure::SumsOf<L> pressure = SymmetricPressure::zero_sums<L>();
  TermSums<L, Terms...> sums;
  List::zero(sums);
  for_each_candidate_run<L>(grid, self.x, i, true, [&](uint32_t base, const typename L::Mask& valid) {
    ForcePairOf<L> pair;
    pair.d = lanes_self.x - load3<L>(c.x, c.y, c.z, base);
    pair.r2 = length_squared(pair.d);
    pair.neighbor = valid && pair.r2 < h2;
    if (!any(pair.neighbor)) return;
    pair.pressure = kPressure ? L::load(c.pressure + base) : zero;
    pair.v = load3<L>(c.vx, c.vy, c.vz, base);
    pair.inv_density = L::load(c.inv_density + base);
    pair.r = square_root(pair.r2);
    pair.pair_neighbors =
        List::kReadsNeighborCounts ? lanes_self.neighbor_count + L::load(c.neighbor_count + base) : zero;
    if (List::kReadsColourNormals) {
      pair.normal = load3<L>(c.normal_x, c.normal_y, c.normal_z, base);
      pair.normal_length = L::load(c.normal_length + base);
    } else {
      pair.normal = Vec3Of<L>{zero, zero, zero};
      pair.normal_length = zero;
    }
    if (kPressure) SymmetricPressure::add_pair(f, lanes_self, pair, pressure);
    List::add(f, lanes_self, pair, sums);
  });
  const SymmetricPressure::Sums pressure_sums =
      reduce_term_sums<SymmetricPressure::Sums, SymmetricPressure::SumsOf<L>, L>(pressure);
  TermSums<float, Terms...> term_sums;
  reduce_term_list(sums, term_sums);
  return finish_acceleration<List, TermSums<float, Terms...>, kPressure>(f, self, pressure_sums, term_sums);
}

template <class L, bool kPressure, class... Terms>
SimdPasses::AccelerationFn acceleration_of(ForceTerms<Terms...>) {
  return &acceleration<L, kPressure, Terms...>;
}

template <class L>
SimdPasses::AccelerationFn acceleration_for(const MethodSelection& s) {
  return with_force_terms(s, [](auto terms) { return acceleration_of<L, true>(terms); });
}

template <class L>
SimdPasses::AccelerationFn acceleration_without_pressure_for(const MethodSelection& s) {
  return with_force_terms(s, [](auto terms) { return acceleration_of<L, false>(terms); });
}

template <class L>
constexpr SimdPasses make_simd_passes(SimdTarget target, const char* name) {
  return SimdPasses{target,
                    name,
                    &density<L>,
                    &normalized_density<L>,
                    &density_diffusion<L>,
                    &colour_normal<L>,
                    &acceleration_for<L>,
                    &acceleration_without_pressure_for<L>,
                    &dfsph_density_and_factor<L>,
                    &dfsph_density_rate<L>,
                    &dfsph_velocity_change<L, false>,
                    &dfsph_velocity_change<L, true>};
}

}  // namespace simd
}  // namespace sph
