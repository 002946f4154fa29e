// SPDX-License-Identifier: MIT
// The per-particle arrays of a physics method, declared as data by the method's module (its
// kArrays). Both backends' particle stores allocate them from these records and give each the
// bookkeeping of its role, and checkpoints carry the carried ones by name, so a method's arrays
// need no edits in a store (docs/architecture.md, "The methods' per-particle arrays").
#pragma once

#include <stdint.h>

namespace sph {

enum class ParticleArrayRole : uint32_t {
  // Lives through one pass or one force evaluation: written and read in the same order, never
  // reordered, never saved. (Larger roles below do everything this one does.)
  Scratch = 0,
  // Lives through one substep: follows every reorder inside it (the sorts of the RK4 stages, a
  // sink's compaction), but is neither snapshotted nor saved.
  Sorted = 1,
  // State carried from frame to frame: follows every reorder, is copied by the rollback snapshot
  // at the start of a frame, and is saved in checkpoints (ParticleSnapshot::carried).
  Carried = 2,
};

struct ParticleArraySpec {
  const char* name;        // unique per world; the checkpoint's key for a carried array
  uint32_t element_size;   // bytes of one element (a multiple of 4)
  ParticleArrayRole role;  // what the stores do with it
  // Elements per particle (kSpringSlots link candidates per particle, say); 0: one element for
  // the whole world, not per particle (a method's world word, e.g. springs' link_from).
  uint32_t elements_per_particle;
  const void* initial;  // element_size bytes a new particle's element starts as; null: zero bytes
  // Elements that hold storage indices of other particles rewrite them when the particles are
  // reordered (new_index_of_old[old] is the new index, or 0xffffffff for a removed particle).
  void (*rewrite_indices)(void* element, const uint32_t* new_index_of_old);
};

// The names by which backends and checkpoints look today's methods' arrays up.
constexpr const char* kArrayNeighborCount = "neighbor_count";            // Clavet viscosity, uint32
constexpr const char* kArrayDensityFactor = "density_factor";            // normalised density, float
constexpr const char* kArrayNormalizedDensity = "normalized_density";    // normalised density, float
constexpr const char* kArrayColourNormal = "colour_normal";              // surface tension, Float4
constexpr const char* kArraySprings = "springs";                         // springs, SpringList
constexpr const char* kArraySpringLinkFrom = "spring_link_from";         // springs, one uint32 per world
constexpr const char* kArraySpringCandidates = "spring_candidates";      // springs, kSpringSlots uint32
constexpr const char* kArraySpringAcceleration = "spring_acceleration";  // springs, Float4

}  // namespace sph
