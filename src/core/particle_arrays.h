// SPDX-License-Identifier: MIT
// The per-particle arrays a world needs: the core state, each running method's own (declared by
// the method's module as ParticleArraySpec records, physics/particle_array_spec.h) and the
// integrator's. Both backends' particle stores allocate from this list.
#pragma once

#include <stdint.h>

#include <vector>

#include "../physics/particle_array_spec.h"
#include "config.h"

namespace sph {

// The core state every world carries (ParticleSnapshot has fields for it).
constexpr const char* kArrayPosition = "position";  // Float4, w: pressure after the density pass
constexpr const char* kArrayVelocity = "velocity";  // Float4, w: 1 / density after the density pass
constexpr const char* kArrayId = "id";              // uint32
constexpr const char* kArrayDensity = "density";    // float
// SPH_FEATURE_USER_ATTRIBUTE: the caller's uint32 per particle, carried (0 for a new particle
// unless its source gives another).
constexpr const char* kArrayUserAttribute = "user_attribute";

// Names of the integrator's arrays (the methods' own are in physics/particle_array_spec.h).
constexpr const char* kArrayRk4Start = "rk4_start";  // RK4, ParticleState
constexpr const char* kArrayRk4Sum = "rk4_sum";      // RK4, Rk4Accumulator

// The arrays the world's methods need beyond the core state (position, velocity, id, density):
// each running method's kArrays in the method list's order (physics/methods.h), then the
// integrator's, then the user attribute's.
std::vector<ParticleArraySpec> method_particle_arrays(const WorldConfig& config);

// The spec of that name in specs, or null.
const ParticleArraySpec* find_array_spec(const std::vector<ParticleArraySpec>& specs, const char* name);

// Bytes of one particle's share of an array (0 for a world word).
inline uint64_t particle_bytes(const ParticleArraySpec& s) {
  return static_cast<uint64_t>(s.element_size) * s.elements_per_particle;
}

}  // namespace sph
