// The CPU backend: the reference solver. Each substep sorts particles into the wrapped grid,
// then loops the shared per-particle physics (src/physics) over all particles on OpenMP
// threads. Results do not depend on the thread count: every particle is a pure gather and
// the only reduction (max speed) is order-independent.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "../core/backend.h"
#include "../core/grid_layout.h"
#include "../core/status.h"
#include "../physics/density.h"
#include "../physics/forces.h"
#include "../physics/integrate.h"
#include "cpu_neighbor_grid.h"
#include "host_particle_store.h"

namespace sph {
namespace {

using Clock = std::chrono::steady_clock;

double elapsed_ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

bool finite3(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

class CpuBackend final : public Backend {
 public:
  CpuBackend(const WorldConfig& config, unsigned workers)
      : config_(config),
        workers_(workers == 0 ? 1u : workers),
        grid_(make_grid_shape(config.kernel_radius, config.capacity)),
        position_(store_.add<Float4>()),  // w: pressure after the density pass
        velocity_(store_.add<Float4>()),  // w: 1 / density after the density pass
        id_(store_.add<uint32_t>()),
        density_(store_.add<float>()),
        neighbors_(store_.add<uint32_t>()) {
    if (config.integrator == Integrator::Rk4) {
      // Only an RK4 world pays for the start state and the slope accumulators.
      rk4_start_ = &store_.add<ParticleState>();
      rk4_sum_ = &store_.add<Rk4Accumulator>();
    }
  }

  uint32_t particle_count() const override { return count_; }

  void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id) override {
    const uint32_t total = count_ + n;
    store_.resize(total);  // std::bad_alloc leaves count_ unchanged; the C layer maps it
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t i = count_ + k;
      const Vec3 v = velocities ? velocities[k] : Vec3{0.0f, 0.0f, 0.0f};
      position_.data[i] = make_float4_record(positions[k], 0.0f);
      velocity_.data[i] = make_float4_record(v, 1.0f / config_.rest_density);
      id_.data[i] = first_id + k;
      density_.data[i] = config_.rest_density;
      neighbors_.data[i] = 0;
    }
    count_ = total;
    max_speed_valid_ = false;
  }

  FrameReport step_frame(double frame_dt, const RuntimeParams& params) override {
    FrameReport report;
    const FluidConstants fluid = make_fluid_constants(config_, params);
    const StepLimits limits = make_step_limits(config_, params);
    const auto saved = store_.snapshot();
    const float saved_max_speed = max_speed_;
    const bool saved_max_speed_valid = max_speed_valid_;
    if (!max_speed_valid_) max_speed_ = compute_max_speed();

    double remaining = frame_dt;
    report.dt_min = std::numeric_limits<float>::max();
    while (remaining > 0.0 && report.substeps < params.max_substeps) {
      const double dt = landing_dt(controller_dt(limits, max_speed_), remaining);
      const float dtf = static_cast<float>(dt);
      const uint32_t bad = config_.integrator == Integrator::Rk4 ? substep_rk4(fluid, dtf, report)
                                                                 : substep_euler(fluid, dtf, report);
      if (bad != kAllFinite) {
        store_.restore(saved);
        max_speed_ = saved_max_speed;
        max_speed_valid_ = saved_max_speed_valid;
        throw Error(Status::NonFinite, "the step produced a non-finite position or velocity in substep " +
                                           std::to_string(report.substeps + 1) + " (dt " +
                                           std::to_string(dtf) + " s) at particle id " + std::to_string(bad) +
                                           "; the world was restored to its state before sph_world_step");
      }
      remaining -= dt;
      ++report.substeps;
      report.time_advanced += dt;
      report.dt_min = std::min(report.dt_min, dtf);
      report.dt_max = std::max(report.dt_max, dtf);
    }
    if (report.substeps == 0) report.dt_min = 0.0f;
    report.completed = remaining <= 0.0;
    report.max_speed = max_speed_;
    const auto t = Clock::now();
    summarize(report);
    report.stage_ms[kStageOther] += static_cast<float>(elapsed_ms(t));
    return report;
  }

  void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                      size_t stride) const override {
    unsigned char* out = static_cast<unsigned char*>(dst);
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t i = first + k;
      unsigned char* p = out + static_cast<size_t>(k) * stride;
      switch (kind) {
        case AttributeKind::Position: {
          const float v[3] = {position_.data[i].x, position_.data[i].y, position_.data[i].z};
          std::memcpy(p, v, sizeof v);
          break;
        }
        case AttributeKind::Velocity: {
          const float v[3] = {velocity_.data[i].x, velocity_.data[i].y, velocity_.data[i].z};
          std::memcpy(p, v, sizeof v);
          break;
        }
        case AttributeKind::Density:
          std::memcpy(p, &density_.data[i], sizeof(float));
          break;
        case AttributeKind::Pressure:
          std::memcpy(p, &position_.data[i].w, sizeof(float));
          break;
        case AttributeKind::Id:
          std::memcpy(p, &id_.data[i], sizeof(uint32_t));
          break;
      }
    }
  }

  uint64_t memory_bytes() const override { return store_.bytes() + grid_.bytes(); }

 private:
  static constexpr uint32_t kAllFinite = 0xffffffffu;

  int n() const { return static_cast<int>(count_); }

  float compute_max_speed() const {
    float v2max = 0.0f;
#pragma omp parallel for num_threads(workers_) schedule(static) reduction(max : v2max)
    for (int i = 0; i < n(); ++i) v2max = std::max(v2max, length_squared(xyz(velocity_.data[i])));
    return std::sqrt(v2max);
  }

  // Hash, sort, reorder every attribute, then density and pressure (packed into the w slots).
  void sort_and_density(const FluidConstants& fluid, FrameReport& report) {
    auto t = Clock::now();
    grid_.build(position_.data.data(), count_, workers_);
    store_.permute(grid_.order().data(), count_);
    report.stage_ms[kStageHashSort] += static_cast<float>(elapsed_ms(t));

    t = Clock::now();
    const GridView view = grid_.view();
    Float4* pos = position_.data.data();
    Float4* vel = velocity_.data.data();
#pragma omp parallel for num_threads(workers_) schedule(static)
    for (int i = 0; i < n(); ++i) {
      const DensitySample s = gather_density(fluid, view, pos, static_cast<uint32_t>(i));
      density_.data[i] = s.density;
      neighbors_.data[i] = s.neighbor_count;
      // Only the w slots are written; neighbours read x, y, z alone.
      pos[i].w = pressure_from_density(s.density, fluid.rest_density, fluid.stiffness);
      vel[i].w = 1.0f / s.density;
    }
    report.stage_ms[kStageDensity] += static_cast<float>(elapsed_ms(t));
  }

  uint32_t substep_euler(const FluidConstants& fluid, float dt, FrameReport& report) {
    sort_and_density(fluid, report);
    auto t = Clock::now();
    const GridView view = grid_.view();
    next_position_.resize(count_);
    next_velocity_.resize(count_);
    const Float4* pos = position_.data.data();
    const Float4* vel = velocity_.data.data();
    float v2max = 0.0f;
    uint32_t bad_index = kAllFinite;
#pragma omp parallel for num_threads(workers_) schedule(static) reduction(max                    \
                                                                          : v2max) reduction(min \
                                                                                             : bad_index)
    for (int i = 0; i < n(); ++i) {
      const Vec3 a = gather_acceleration(fluid, view, pos, vel, static_cast<uint32_t>(i));
      const ParticleState s = symplectic_euler({xyz(pos[i]), xyz(vel[i])}, a, dt);
      next_position_[i] = make_float4_record(s.position, pos[i].w);
      next_velocity_[i] = make_float4_record(s.velocity, vel[i].w);
      const float v2 = length_squared(s.velocity);
      v2max = std::max(v2max, v2);
      if (!finite3(s.position) || !std::isfinite(v2))
        bad_index = std::min(bad_index, static_cast<uint32_t>(i));
    }
    report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
    t = Clock::now();
    position_.data.swap(next_position_);
    velocity_.data.swap(next_velocity_);
    max_speed_ = std::sqrt(v2max);
    max_speed_valid_ = true;
    report.stage_ms[kStageIntegrate] += static_cast<float>(elapsed_ms(t));
    return bad_index == kAllFinite ? kAllFinite : id_.data[bad_index];
  }

  uint32_t substep_rk4(const FluidConstants& fluid, float dt, FrameReport& report) {
    // Stage 0 starts from the current state.
    for (int i = 0; i < n(); ++i)
      rk4_start_->data[i] = ParticleState{xyz(position_.data[i]), xyz(velocity_.data[i])};
    float v2max = 0.0f;
    uint32_t bad_index = kAllFinite;
    for (int stage = 0; stage < 4; ++stage) {
      sort_and_density(fluid, report);
      auto t = Clock::now();
      const GridView view = grid_.view();
      next_position_.resize(count_);
      next_velocity_.resize(count_);
      const Float4* pos = position_.data.data();
      const Float4* vel = velocity_.data.data();
      v2max = 0.0f;
      bad_index = kAllFinite;
#pragma omp parallel for num_threads(workers_) schedule(static) reduction(max                    \
                                                                          : v2max) reduction(min \
                                                                                             : bad_index)
      for (int i = 0; i < n(); ++i) {
        const Vec3 a = gather_acceleration(fluid, view, pos, vel, static_cast<uint32_t>(i));
        const ParticleState s =
            rk4_advance(stage, rk4_start_->data[i], {xyz(pos[i]), xyz(vel[i])}, a, dt, rk4_sum_->data[i]);
        next_position_[i] = make_float4_record(s.position, pos[i].w);
        next_velocity_[i] = make_float4_record(s.velocity, vel[i].w);
        const float v2 = length_squared(s.velocity);
        v2max = std::max(v2max, v2);
        if (!finite3(s.position) || !std::isfinite(v2))
          bad_index = std::min(bad_index, static_cast<uint32_t>(i));
      }
      report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
      position_.data.swap(next_position_);
      velocity_.data.swap(next_velocity_);
      if (bad_index != kAllFinite) break;
    }
    max_speed_ = std::sqrt(v2max);
    max_speed_valid_ = true;
    return bad_index == kAllFinite ? kAllFinite : id_.data[bad_index];
  }

  // Density and neighbour statistics of the last density evaluation.
  void summarize(FrameReport& report) const {
    if (count_ == 0) return;
    double sum = 0.0, neighbor_sum = 0.0;
    float lo = density_.data[0], hi = density_.data[0];
    uint32_t neighbor_max = 0;
    for (uint32_t i = 0; i < count_; ++i) {
      const float d = density_.data[i];
      sum += d;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
      neighbor_sum += neighbors_.data[i];
      neighbor_max = std::max(neighbor_max, neighbors_.data[i]);
    }
    report.density_min = lo;
    report.density_max = hi;
    report.density_mean = static_cast<float>(sum / count_);
    report.neighbors_mean = static_cast<float>(neighbor_sum / count_);
    report.neighbors_max = neighbor_max;
  }

  WorldConfig config_;
  unsigned workers_;
  CpuNeighborGrid grid_;
  HostParticleStore store_;
  HostArray<Float4>& position_;
  HostArray<Float4>& velocity_;
  HostArray<uint32_t>& id_;
  HostArray<float>& density_;
  HostArray<uint32_t>& neighbors_;
  HostArray<ParticleState>* rk4_start_ = nullptr;
  HostArray<Rk4Accumulator>* rk4_sum_ = nullptr;
  // Integration writes here and swaps, so the force gather reads a state nobody writes.
  std::vector<Float4> next_position_;
  std::vector<Float4> next_velocity_;
  uint32_t count_ = 0;
  float max_speed_ = 0.0f;
  bool max_speed_valid_ = false;
};

}  // namespace

std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count) {
  return std::make_unique<CpuBackend>(config, worker_count);
}

}  // namespace sph
