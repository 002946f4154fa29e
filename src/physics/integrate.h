// SPDX-License-Identifier: MIT
// Time integration of one particle: symplectic Euler and the classic RK4 stage updates.
#pragma once

#include "host_device.h"
#include "vec3.h"

namespace sph {

struct ParticleState {
  Vec3 position;
  Vec3 velocity;
};

// Symplectic (semi-implicit) Euler: velocity first, then position with the new velocity.
SPH_HD ParticleState symplectic_euler(ParticleState s, Vec3 acceleration, float dt) {
  ParticleState out;
  out.velocity = s.velocity + acceleration * dt;
  out.position = s.position + out.velocity * dt;
  return out;
}

// RK4 weights of stages 1..4 in the final combination, and where each stage is evaluated
// (as a fraction of dt from the start state).
SPH_HD float rk4_weight(int stage) { return (stage == 0 || stage == 3) ? 1.0f / 6.0f : 2.0f / 6.0f; }
SPH_HD float rk4_stage_offset(int stage) { return stage == 0 ? 0.0f : (stage == 3 ? 1.0f : 0.5f); }

// After evaluating stage `stage` (derivatives: dx/dt = velocity, dv/dt = acceleration):
// accumulates its weighted slope and returns the state where the next stage is evaluated,
// or, after the last stage, the final state start + dt * sum.
struct Rk4Accumulator {
  Vec3 position_slope_sum;
  Vec3 velocity_slope_sum;
};

SPH_HD ParticleState rk4_advance(int stage, const ParticleState& start, const ParticleState& current,
                                 Vec3 acceleration, float dt, Rk4Accumulator& acc) {
  const float w = rk4_weight(stage);
  if (stage == 0) {
    acc.position_slope_sum = current.velocity * w;
    acc.velocity_slope_sum = acceleration * w;
  } else {
    acc.position_slope_sum += current.velocity * w;
    acc.velocity_slope_sum += acceleration * w;
  }
  ParticleState next;
  if (stage == 3) {
    next.position = start.position + acc.position_slope_sum * dt;
    next.velocity = start.velocity + acc.velocity_slope_sum * dt;
  } else {
    const float h = rk4_stage_offset(stage + 1) * dt;
    next.position = start.position + current.velocity * h;
    next.velocity = start.velocity + acceleration * h;
  }
  return next;
}

}  // namespace sph
