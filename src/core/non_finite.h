// SPDX-License-Identifier: MIT
// A substep that produced a non-finite state, written once for both backends: which stage of a
// particle went non-finite first (classify_non_finite, on the device too) and the error message
// (non_finite_message). Both backends name the particle with the lowest storage index whose new
// state is not finite, and classify it by recomputing nothing but what the substep computed.
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "../physics/float4_types.h"
#include "../physics/host_device.h"
#include "../physics/integrate.h"
#include "../physics/step_control.h"
#include "../physics/vec3.h"
#include "host_memory.h"

#if defined(__CUDACC__)
#define SPH_ISFINITE isfinite
#else
#include <cmath>
#define SPH_ISFINITE std::isfinite
#endif

namespace sph {

// The stages in the order a particle's substep runs them (the sph_stage names of the message).
enum NonFiniteStage : uint32_t {
  kNonFiniteDensity = 0,    // its density or pressure
  kNonFiniteForces = 1,     // its acceleration (pair terms, springs, force fields)
  kNonFiniteIntegrate = 2,  // its integrated state, before the colliders
  kNonFiniteCollide = 3     // the collision response
};

SPH_HD bool finite3(Vec3 v) { return SPH_ISFINITE(v.x) && SPH_ISFINITE(v.y) && SPH_ISFINITE(v.z); }

// Whether a particle's new state is finite, the test of every substep's scan: its position, its
// speed's square, and the density pass's records the state carries, its pressure (position.w)
// and 1 / density (velocity.w). Those two reach the attributes, the probes and checkpoints (whose
// reader refuses a non-finite one), and a particle without neighbours moves on finitely whatever
// they hold: found by fuzz_capi, a lone particle of a world with rest_density 3e38 kept a pressure
// of +Inf through a successful step, and the world's own checkpoint did not load.
SPH_HD bool state_finite(Vec3 position, float pressure, float speed_squared, float inverse_density) {
  return finite3(position) && SPH_ISFINITE(speed_squared) && SPH_ISFINITE(pressure) &&
         SPH_ISFINITE(inverse_density);
}
SPH_HD bool state_finite(const Float4& position, const Float4& velocity) {
  return state_finite(xyz(position), position.w, length_squared(xyz(velocity)), velocity.w);
}

// The new state of a particle is not finite: the first of its stages whose result is not.
// position.w is its pressure and velocity.w its 1 / density (the records of the density pass).
SPH_HD uint32_t classify_non_finite(float density, const Float4& position, const Float4& velocity,
                                    Vec3 acceleration, const ParticleState& integrated) {
  if (!SPH_ISFINITE(density) || !SPH_ISFINITE(position.w) || !SPH_ISFINITE(velocity.w))
    return kNonFiniteDensity;
  if (!finite3(acceleration)) return kNonFiniteForces;
  if (!finite3(integrated.position) || !SPH_ISFINITE(length_squared(integrated.velocity)))
    return kNonFiniteIntegrate;
  return kNonFiniteCollide;
}

// What a backend found about the failed substep.
struct NonFiniteFailure {
  uint32_t stage = kNonFiniteDensity;  // NonFiniteStage of the first particle
  uint32_t substep = 0;                // 1 for the frame's first substep
  float dt = 0.0f;                     // the failed substep's step, s
  uint32_t count = 0;                  // particles whose new state is not finite
  HostVector<uint32_t> ids;            // some of their ids, the first particle's first
};

// "the step produced non-finite values in the forces stage (SPH_STAGE_FORCES) of substep 3 (dt
// 0.001 s): 2 particles, ids 17, 20; the world was restored to its state before sph_world_step",
// with the stability ceiling named when dt_min forced a step above it.
std::string non_finite_message(const NonFiniteFailure& failure, const StepLimits& limits);

}  // namespace sph
