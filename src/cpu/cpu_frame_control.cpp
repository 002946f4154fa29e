// The CPU backend's end of a substep: the max-speed reduction, the non-finite check and its
// diagnosis, and the swap to the new state (the twin of cuda/frame_control.cu).
#include <algorithm>
#include <cmath>
#include <string>

#include "cpu_backend_impl.h"

namespace sph {

float CpuBackend::compute_max_speed() const {
  float v2max = 0.0f;
#pragma omp parallel for num_threads(threads()) schedule(static) reduction(max : v2max)
  for (int i = 0; i < n(); ++i) v2max = std::max(v2max, length_squared(xyz(velocity_.data[i])));
  return std::sqrt(v2max);
}

// Max speed and the first non-finite particle of the state in next_*.
uint32_t CpuBackend::scan_next_state(float& v2max) const {
  float m = 0.0f;
  uint32_t bad_index = kAllFinite;
#pragma omp parallel for num_threads(threads()) schedule(static) reduction(max : m) reduction(min : bad_index)
  for (int i = 0; i < n(); ++i) {
    const float v2 = length_squared(xyz(next_velocity_[i]));
    m = std::max(m, v2);
    if (!finite3(xyz(next_position_[i])) || !std::isfinite(v2))
      bad_index = std::min(bad_index, static_cast<uint32_t>(i));
  }
  v2max = m;
  return bad_index;
}

// Says when a failed substep was longer than the stability ceiling (only dt_min can force it).
std::string CpuBackend::above_stable_step(float dt, const StepLimits& limits) {
  if (!(limits.stability_dt > 0.0f) || dt <= limits.stability_dt) return "";
  return ", above this world's stable step " + std::to_string(limits.stability_dt) +
         " s (0.4 h / c, 0.05 h^2 rho0 / mu), forced by dt_min";
}

// Where a failed substep went non-finite, worked out on the failure path only, before the new
// state replaces the old: the particle with the lowest index names the stage (the first of
// its density and pressure, its acceleration, its integrated state and the collision response
// that is not finite; the CUDA backend names the same), and up to 8 ids are listed.
void CpuBackend::diagnose_non_finite(const FluidConstants& fluid, const SceneFrame& scene, int rk4_stage,
                                     uint32_t first) {
  const Float4* pos = position_.data.data();
  const Float4* vel = velocity_.data.data();
  const uint32_t i = first;
  const char* stage = "collide stage (SPH_STAGE_COLLIDE)";
  if (!std::isfinite(density_.data[i]) || !std::isfinite(pos[i].w) || !std::isfinite(vel[i].w)) {
    stage = "density stage (SPH_STAGE_DENSITY)";
  } else {
    Vec3 a = acceleration_function()(fluid, grid_.view(), pos, vel, neighbors_.data.data(), normals_.data(),
                                     scene, i);
    if (springs_) a += spring_acceleration_[i];
    if (!finite3(a)) {
      stage = "forces stage (SPH_STAGE_FORCES)";
    } else if (rk4_stage >= 0) {
      // The RK4 sums were updated in place, so the integrated state cannot be recomputed.
      stage = rk4_stage == 3 && !scene.colliders.empty() ? "integrate or collide stage (RK4 stage 4)"
                                                         : "integrate stage (SPH_STAGE_INTEGRATE)";
    } else {
      const ParticleState s = symplectic_euler({xyz(pos[i]), xyz(vel[i])}, a, fluid.dt);
      if (!finite3(s.position) || !std::isfinite(length_squared(s.velocity)))
        stage = "integrate stage (SPH_STAGE_INTEGRATE)";
    }
  }
  uint32_t count = 0;
  std::string ids;
  for (uint32_t k = 0; k < count_; ++k) {
    if (finite3(xyz(next_position_[k])) && std::isfinite(length_squared(xyz(next_velocity_[k])))) continue;
    if (++count <= 8) ids += (count > 1 ? ", " : "") + std::to_string(id_.data[k]);
  }
  non_finite_.where = stage;
  non_finite_.particles = std::to_string(count) + (count == 1 ? " particle, id " : " particles, ids ") + ids +
                          (count > 8 ? ", ..." : "");
}

uint32_t CpuBackend::finish_substep(float v2max, uint32_t bad_index) {
  position_.data.swap(next_position_);
  velocity_.data.swap(next_velocity_);
  max_speed_ = std::sqrt(v2max);
  max_speed_valid_ = true;
  return bad_index == kAllFinite ? kAllFinite : id_.data[bad_index];
}

}  // namespace sph
