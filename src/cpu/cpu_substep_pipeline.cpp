// SPDX-License-Identifier: MIT
// The order of the CPU backend's passes in one substep: symplectic Euler (sort, density,
// springs, forces + integration, colliders) or the four stages of RK4 (the twin of
// cuda/substep_pipeline.cu).
#include <algorithm>
#include <cmath>

#include "cpu_backend_impl.h"

namespace sph {

// Resolves colliders for the state in next_position_/next_velocity_, moved from x_old(i).
template <class OldPosition>
void CpuBackend::collide(const SceneFrame& scene, const SubstepTime& time, OldPosition&& x_old,
                         FrameReport& report) {
  if (scene.colliders.empty()) return;
  const auto t = stage_start();
  const float h = config_.kernel_radius;
  Float4* next_pos = next_position_.data();
  Float4* next_vel = next_velocity_.data();
  const uint32_t* origin = origins();  // null unless distributed
  parallel().for_each(count_, [&](uint32_t i) {
    if (origin && origin[i]) return;  // (a distributed world's halo: its owner moves it)
    Vec3 x = xyz(next_pos[i]);
    Vec3 v = xyz(next_vel[i]);
    const Vec3 from = x_old(static_cast<uint32_t>(i));
    for (const ColliderFrame& c : scene.colliders) collide_particle(c.view, time, h, from, x, v);
    next_pos[i] = make_float4_record(x, next_pos[i].w);
    next_vel[i] = make_float4_record(v, next_vel[i].w);
  });
  end_stage(report, kStageCollide, t);
}

void CpuBackend::collide_from(const SceneFrame& scene, const SubstepTime& time, const Float4* old,
                              FrameReport& report) {
  collide(
      scene, time, [old](uint32_t i) { return xyz(old[i]); }, report);
}

uint32_t CpuBackend::substep_euler(const FluidConstants& fluid, const SceneFrame& scene,
                                   const SubstepTime& time, FrameReport& report) {
  sort_and_density(fluid, scene, stage_time(time, 0.0f), report, time.dt);
  sample_probes(scene, time.dt, report);
  spring_pass(time.dt, true, report);
  auto t = stage_start();
  const GridView view = grid_.view();
  Float4* next_pos = next_position_.data();
  Float4* next_vel = next_velocity_.data();
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  const Float4* spring = spring_acceleration_.data();
  const float dt = time.dt;
  const AccelerationFn gather = acceleration_function();
  const NeighborColumns columns = columns_.view();
  // With nothing to move the new state after the integration (no colliders, no loads), the
  // end-of-substep scan (max speed, first non-finite particle) rides in the force loop: one pass
  // over the particles less. Both reductions are order-independent, so the bits are the scan's.
  const bool scan_in_loop = scene.colliders.empty() && !loads_on();
  const uint32_t* origin = origins();  // null unless distributed
  const StateScan forces = parallel().reduce(
      count_, StateScan{},
      [&](uint32_t i, StateScan& r) {
        if (origin && origin[i]) return;  // (a distributed world's halo: its owner moves it)
        Vec3 a = acceleration(gather, fluid, view, columns, scene, i);
        if (spring) a += xyz(spring[i]);
        a += wall_acceleration(i);
        r.a2max = std::max(r.a2max, length_squared(a));
        const ParticleState s = symplectic_euler({xyz(pos[i]), xyz(vel[i])}, a, dt);
        next_pos[i] = make_float4_record(s.position, pos[i].w);
        next_vel[i] = make_float4_record(s.velocity, vel[i].w);
        if (scan_in_loop) {
          const float v2 = length_squared(s.velocity);
          r.v2max = std::max(r.v2max, v2);
          if (!state_finite(s.position, pos[i].w, v2, vel[i].w)) r.bad_index = std::min(r.bad_index, i);
        }
      },
      combine_scans);
  float v2max = forces.v2max;
  uint32_t bad_index = forces.bad_index;
  max_acceleration_ = std::sqrt(forces.a2max);
  end_stage(report, kStageForces, t);
  if (loads_on()) {
    OldPositions old;
    old.records = pos;
    collide_with_loads(fluid, scene, time, stage_time(time, 0.0f), dt, old, report);
  } else {
    collide(
        scene, time, [&](uint32_t i) { return xyz(pos[i]); }, report);
  }
  t = stage_start();
  if (!scan_in_loop) bad_index = scan_next_state(v2max);
  if (bad_index != kAllFinite) diagnose_non_finite(fluid, scene, -1, bad_index);
  const uint32_t bad = finish_substep(v2max, bad_index);
  end_stage(report, kStageIntegrate, t);
  return bad;
}

uint32_t CpuBackend::substep_rk4(const FluidConstants& fluid, const SceneFrame& scene,
                                 const SubstepTime& time, FrameReport& report) {
  // Stage 0 starts from the current state.
  for (int i = 0; i < n(); ++i)
    rk4_start_[i] = ParticleState{xyz(position_[i]), xyz(velocity_[i])};  // (not a hot loop)
  const float dt = time.dt;
  const AccelerationFn gather = acceleration_function();
  float a2max = 0.0f;
  for (int stage = 0; stage < 4; ++stage) {
    // The density diffusion once per substep, for its whole dt.
    sort_and_density(fluid, scene, stage_time(time, rk4_stage_fraction(stage)), report,
                     stage == 0 ? dt : 0.0f);
    if (stage == 0) sample_probes(scene, dt, report);  // the substep's start, as with Euler
    spring_pass(dt, stage == 0, report);
    auto t = stage_start();
    const GridView view = grid_.view();
    Float4* next_pos = next_position_.data();
    Float4* next_vel = next_velocity_.data();
    const Float4* pos = position_.data();
    const Float4* vel = velocity_.data();
    const Float4* spring = spring_acceleration_.data();
    const NeighborColumns columns = columns_.view();
    const ParticleState* start = rk4_start_.data();
    Rk4Accumulator* sums = rk4_sum_.data();
    const uint32_t* origin = origins();  // null unless distributed
    const float stage_a2max = parallel().reduce(
        count_, 0.0f,
        [&](uint32_t i, float& m) {
          if (origin && origin[i]) return;  // (a distributed world's halo: its owner moves it)
          Vec3 a = acceleration(gather, fluid, view, columns, scene, i);
          if (spring) a += xyz(spring[i]);
          a += wall_acceleration(i);
          m = std::max(m, length_squared(a));
          const ParticleState s = rk4_advance(stage, start[i], {xyz(pos[i]), xyz(vel[i])}, a, dt, sums[i]);
          next_pos[i] = make_float4_record(s.position, pos[i].w);
          next_vel[i] = make_float4_record(s.velocity, vel[i].w);
        },
        [](float a, float b) { return std::max(a, b); });
    a2max = std::max(a2max, stage_a2max);
    end_stage(report, kStageForces, t);
    if (loads_on() && (boundary_ || stage == 3)) {  // the walls' reactions, the contacts after the last
      OldPositions old;
      if (stage == 3) old.states = start;
      collide_with_loads(fluid, scene, time, stage_time(time, rk4_stage_fraction(stage)),
                         rk4_weight(stage) * dt, old, report);
    } else if (stage == 3) {
      collide(
          scene, time, [start](uint32_t i) { return start[i].position; }, report);
    }
    t = stage_start();
    float v2max = 0.0f;
    const uint32_t bad_index = scan_next_state(v2max);
    if (bad_index != kAllFinite) diagnose_non_finite(fluid, scene, stage, bad_index);
    uint32_t bad = finish_substep(v2max, bad_index);
    // A distributed world's stage ends as a substep does: the ghosts go (the next stage's sort
    // gathers them anew) and the ranks agree on a failure, so all stop at the same stage.
    if (rank_) bad = halo_end_substep(bad);
    end_stage(report, kStageIntegrate, t);
    if (bad != kAllFinite) return bad;
  }
  max_acceleration_ = std::sqrt(a2max);
  return kAllFinite;
}

}  // namespace sph
