// SPDX-License-Identifier: MIT
// The CPU backend's end of a substep: the max-speed reduction, the non-finite check and its
// diagnosis, and the swap to the new state (the twin of cuda/frame_control.cu).
#include <algorithm>
#include <cmath>

#include "cpu_backend_impl.h"

namespace sph {

float CpuBackend::compute_max_speed() const {
  const Float4* vel = velocity_.data();
  const float v2max = parallel().reduce(
      count_, 0.0f, [&](uint32_t i, float& m) { m = std::max(m, length_squared(xyz(vel[i]))); },
      [](float a, float b) { return std::max(a, b); });
  return std::sqrt(v2max);
}

// Min and max are exact in any order, so the span is the same bits whatever the workers and, over
// the ranks, whatever the decomposition.
CpuBackend::HeightSpan CpuBackend::measure_height_span() const {
  const Float4* pos = position_.data();
  return parallel().reduce(
      count_, HeightSpan{},
      [&](uint32_t i, HeightSpan& s) {
        const float y = height_along(frame_limits_, xyz(pos[i]));
        s.lo = std::fmin(s.lo, y);
        s.hi = std::fmax(s.hi, y);
      },
      [](HeightSpan a, const HeightSpan& b) {
        a.lo = std::fmin(a.lo, b.lo);
        a.hi = std::fmax(a.hi, b.hi);
        return a;
      });
}

// Max speed and the first non-finite particle of the state in next_*.
uint32_t CpuBackend::scan_next_state(float& v2max) const {
  const Float4* next_pos = next_position_.data();
  const Float4* next_vel = next_velocity_.data();
  const uint32_t* origin = origins();  // null unless distributed
  const StateScan scan = parallel().reduce(
      count_, StateScan{},
      [&](uint32_t i, StateScan& s) {
        if (origin && origin[i]) return;  // (a distributed world's halo)
        const float v2 = length_squared(xyz(next_vel[i]));
        s.v2max = std::max(s.v2max, v2);
        if (!state_finite(next_pos[i], next_vel[i])) s.bad_index = std::min(s.bad_index, i);
      },
      combine_scans);
  v2max = scan.v2max;
  return scan.bad_index;
}

// Where a failed substep went non-finite, worked out on the failure path only, before the new
// state replaces the old: the particle with the lowest index is classified (non_finite.h, as on
// the CUDA backend) from its density pass, its acceleration and its integrated state, which are
// recomputed here; up to 8 ids are listed.
void CpuBackend::diagnose_non_finite(const FluidConstants& fluid, const SceneFrame& scene, int rk4_stage,
                                     uint32_t first) {
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  const uint32_t i = first;
  Vec3 a = config_.solver == Solver::Dfsph
               ? scalar_acceleration_function()(fluid, grid_.view(), force_inputs(), scene, i)
               : acceleration(acceleration_function(), fluid, grid_.view(), columns_.view(), scene, i);
  if (spring_acceleration_) a += xyz(spring_acceleration_[i]);
  a += wall_acceleration(i);
  const ParticleState current{xyz(pos[i]), xyz(vel[i])};
  ParticleState integrated;
  if (config_.solver == Solver::Dfsph) {
    // DFSPH's velocity comes from its solves, which a recomputation here would repeat: its
    // failure is classified from the density pass and the new state itself, so the solves and
    // the non-pressure accelerations count as the integration (as on the CUDA backend).
    a = Vec3{0.0f, 0.0f, 0.0f};
    integrated = ParticleState{xyz(next_position_[i]), xyz(next_velocity_[i])};
  } else if (rk4_stage < 0) {
    integrated = symplectic_euler(current, a, fluid.dt);
  } else if (rk4_stage < 3) {
    Rk4Accumulator sums = rk4_sum_[i];  // a copy: the stage has updated the sums already
    integrated = rk4_advance(rk4_stage, rk4_start_[i], current, a, fluid.dt, sums);
  } else {
    // The last stage's state is start + dt * sums, and the sums hold all four slopes already:
    // a stage with zero slopes adds nothing to them and returns that state.
    Rk4Accumulator sums = rk4_sum_[i];
    const Vec3 zero{0.0f, 0.0f, 0.0f};
    integrated = rk4_advance(3, rk4_start_[i], ParticleState{current.position, zero}, zero, fluid.dt, sums);
  }
  non_finite_.stage = classify_non_finite(density_[i], pos[i], vel[i], a, integrated);
  non_finite_.count = 0;
  non_finite_.ids.clear();
  for (uint32_t k = 0; k < count_; ++k) {
    if (state_finite(next_position_[k], next_velocity_[k])) continue;
    if (++non_finite_.count <= 8) non_finite_.ids.push_back(id_[k]);
  }
}

uint32_t CpuBackend::finish_substep(float v2max, uint32_t bad_index) {
  store_.swap_contents(*position_.array(), *next_position_.array());
  store_.swap_contents(*velocity_.array(), *next_velocity_.array());
  max_speed_ = std::sqrt(v2max);
  max_speed_valid_ = true;
  return bad_index == kAllFinite ? kAllFinite : id_[bad_index];
}

}  // namespace sph
