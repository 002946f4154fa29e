// SPDX-License-Identifier: MIT
// The force pass's device pieces that the weakly compressible kernels (substep_kernels.cu) and
// DFSPH's (dfsph_solver.cu) share: the masked neighbour gather, the scene's force fields and
// colliders, and the non-finite flag.
#pragma once

#include <stdint.h>
#include <string.h>

#include "../src/core/non_finite.h"
#include "../src/physics/collider_response.h"
#include "../src/physics/force_fields.h"
#include "../src/physics/forces.h"
#include "../src/physics/integrate.h"
#include "frame_state.cuh"
#include "substep_kernels.h"

namespace sph {

// A lane group: G consecutive lanes of a warp (G = 1, 2, 4 or 8) that share one particle's
// gather. Lane `lane` of the group takes the candidates begin + lane, begin + lane + G, ... of
// each run of the walk, in ascending order, and sum() adds the G partial sums in a fixed
// butterfly that leaves the same bits in every lane of the group (IEEE addition commutes), so
// a result depends on G and never on timing. G = 1 is one thread per particle.
template <unsigned G>
struct LaneGroup {
  static_assert(G == 1 || G == 2 || G == 4 || G == 8, "a lane group is 1, 2, 4 or 8 lanes of one warp");
  unsigned lane = 0;            // 0 .. G - 1
  unsigned mask = 0xffffffffu;  // the group's lanes in the warp, for the shuffles

  // The group of thread `t` (its index in the grid): particle t / G.
  __device__ static LaneGroup of_thread(unsigned long long t) {
    LaneGroup g;
    g.lane = static_cast<unsigned>(t % G);
    const unsigned warp_lane = threadIdx.x & 31u;
    g.mask = ((1u << G) - 1u) << (warp_lane & ~(G - 1u));
    return g;
  }
  template <class T>
  __device__ T sum(T v) const {
#pragma unroll
    for (unsigned offset = 1; offset < G; offset <<= 1) v += __shfl_xor_sync(mask, v, offset);
    return v;
  }
  // A struct of floats only (a force term's sums), each summed over the group.
  template <class Sums>
  __device__ void sum_values(Sums& s) const {
    constexpr unsigned kValues = sizeof(Sums) / sizeof(float);
    static_assert(sizeof(Sums) == kValues * sizeof(float), "a term's sums must hold floats only");
    float v[kValues];
    memcpy(v, &s, sizeof s);
#pragma unroll
    for (unsigned k = 0; k < kValues; ++k) v[k] = sum(v[k]);
    memcpy(&s, v, sizeof s);
  }
};

// AccelerationGather::combine_sums's visitor: every sum of the gather over the group.
template <unsigned G>
struct LaneGroupCombine {
  LaneGroup<G> group;
  template <class Sums>
  __device__ void operator()(Sums& s) const {
    group.sum_values(s);
  }
  template <class... Terms>
  __device__ void operator()(TermSums<float, Terms...>& s) const {
    terms(s);
  }
  __device__ void terms(TermSums<float>&) const {}
  template <class Term, class... Rest>
  __device__ void terms(TermSums<float, Term, Rest...>& s) const {
    group.sum_values(s.head);
    terms(s.rest);
  }
};

// gather_acceleration (src/physics/forces.h) for SIMT: the same neighbours and the same
// per-neighbour arithmetic (the composer's AccelerationGather), in two phases per run of up to
// 32 candidates of this lane. First every candidate is only tested (a tight loop: load,
// distance, compare) into a bit mask; then the costly pair terms run for the set bits in
// ascending order. In one pass a warp would run the pair terms whenever any of its 32 threads
// had a neighbour, i.e. for almost every candidate, since only about a fifth of the 27-cell
// candidates are within h. (Collecting a whole particle's neighbours in a shared-memory list
// first, for one longer second phase, measured slower: occupancy and latency.) With a lane
// group of G > 1 each lane sums every G-th candidate of a run and the group adds its partial
// sums before finish (LaneGroup); every lane of the group returns the same acceleration.
// Terms: the world's force terms (methods.h); neighbor_counts and normals may be null unless a
// term reads them. kPressure: with the symmetric pressure force (the weakly compressible
// scheme), or without it (DFSPH's non-pressure accelerations, dfsph_solver.cu).
template <class Terms, bool kPressure = true, unsigned G = 1>
__device__ __forceinline__ Vec3 gather_acceleration_masked(const FluidConstants& f, const GridView& grid,
                                                           const Float4* __restrict__ positions,
                                                           const Float4* __restrict__ velocities,
                                                           const uint32_t* __restrict__ neighbor_counts,
                                                           const Float4* __restrict__ normals, uint32_t i,
                                                           LaneGroup<G> group = LaneGroup<G>{}) {
  AccelerationGather<Terms, kPressure> gather(ForceInputs{positions, velocities, neighbor_counts, normals},
                                              i);
  const Vec3 xi = gather.position();
  for_each_neighbor_range(grid, xi, [&](uint32_t begin, uint32_t end) {
    for (uint32_t base = begin + group.lane; base < end; base += 32u * G) {
      const uint32_t count = min(32u, (end - base + G - 1u) / G);
      uint32_t hits = 0;
#pragma unroll 4
      for (uint32_t k = 0; k < count; ++k) {
        const uint32_t j = base + k * G;
        const float r2 = length_squared(xi - xyz(positions[j]));
        hits |= (is_force_neighbor(f, r2, i, j) ? 1u : 0u) << k;
      }
      while (hits != 0u) {
        const uint32_t j = base + static_cast<uint32_t>(__ffs(hits) - 1) * G;
        hits &= hits - 1u;
        const Float4 pj = positions[j];
        const Vec3 d = xi - xyz(pj);
        gather.add(f, j, pj, d, length_squared(d));
      }
    }
  });
  if (G > 1) gather.combine_sums(LaneGroupCombine<G>{group});
  return gather.finish(f);
}

__device__ __forceinline__ void flag_non_finite(FrameState* s, int stage, uint32_t index, uint32_t id,
                                                uint32_t where) {
  atomicMin(&s->bad_key[stage], ((static_cast<unsigned long long>(index) << 2 | where) << 32) | id);
  atomicAdd(&s->bad_counts[stage], 1u);
}

// The scene's force fields at a particle (after the neighbour gather, as the CPU backend).
__device__ __forceinline__ Vec3 add_force_fields(const DeviceScene& scene, Vec3 acc, Vec3 x) {
  for (uint32_t f = 0; f < scene.field_count; ++f) acc += force_field_acceleration(scene.fields[f], x);
  return acc;
}

// Every collider against the integrated state, moved from x_old during the substep.
__device__ __forceinline__ void collide_all(const DeviceScene& scene, const SubstepTime& time, Vec3 x_old,
                                            ParticleState& s) {
  for (uint32_t c = 0; c < scene.collider_count; ++c)
    collide_particle(scene.colliders[c], time, scene.kernel_radius, x_old, s.position, s.velocity);
}

}  // namespace sph
