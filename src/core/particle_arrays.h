// The per-particle arrays of the physics methods, declared as data. Each method names the arrays
// it needs as {name, element size, role} records; both backends' particle stores allocate them
// from these records and give each the bookkeeping of its role, and the checkpoint carries the
// carried ones by name, so a method's arrays need no edits in a store. The record is plain data
// with no dependency (a physics module can declare its arrays with it).
#pragma once

#include <stdint.h>

#include <vector>

#include "config.h"

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

// The core state every world carries (ParticleSnapshot has fields for it).
constexpr const char* kArrayPosition = "position";  // Float4, w: pressure after the density pass
constexpr const char* kArrayVelocity = "velocity";  // Float4, w: 1 / density after the density pass
constexpr const char* kArrayId = "id";              // uint32
constexpr const char* kArrayDensity = "density";    // float

// The names of the arrays of today's methods, by which backends look them up.
constexpr const char* kArrayNeighborCount = "neighbor_count";            // Clavet viscosity, uint32
constexpr const char* kArrayDensityFactor = "density_factor";            // normalised density, float
constexpr const char* kArrayNormalizedDensity = "normalized_density";    // normalised density, float
constexpr const char* kArrayColourNormal = "colour_normal";              // surface tension, Float4
constexpr const char* kArraySprings = "springs";                         // springs, SpringList
constexpr const char* kArraySpringLinkFrom = "spring_link_from";         // springs, one uint32 per world
constexpr const char* kArraySpringCandidates = "spring_candidates";      // springs, kSpringSlots uint32
constexpr const char* kArraySpringAcceleration = "spring_acceleration";  // springs, Float4
constexpr const char* kArrayRk4Start = "rk4_start";                      // RK4, ParticleState
constexpr const char* kArrayRk4Sum = "rk4_sum";                          // RK4, Rk4Accumulator

// The arrays the world's methods need beyond the core state (position, velocity, id, density),
// in a fixed order. Until each method declares its own, this is where they are listed.
std::vector<ParticleArraySpec> method_particle_arrays(const WorldConfig& config);

// The spec of that name in specs, or null.
const ParticleArraySpec* find_array_spec(const std::vector<ParticleArraySpec>& specs, const char* name);

// Bytes of one particle's share of an array (0 for a world word).
inline uint64_t particle_bytes(const ParticleArraySpec& s) {
  return static_cast<uint64_t>(s.element_size) * s.elements_per_particle;
}

}  // namespace sph
