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
#include "../core/scene_frame.h"
#include "../core/status.h"
#include "../physics/density.h"
#include "../physics/density_normalization.h"
#include "../physics/forces.h"
#include "../physics/integrate.h"
#include "../physics/springs.h"
#include "../physics/surface_tension.h"
#include "cpu_neighbor_grid.h"
#include "host_particle_store.h"
#include "host_spring_array.h"

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
    // Only a world with springs pays for the spring lists.
    if (config.features & kFeatureSprings) springs_ = &store_.add_array(std::make_unique<HostSpringArray>());
    // Normalised density carries a per-particle factor (density_normalization.h): sorted, rolled
    // back and checkpointed with the particles; allocated only when the feature is on.
    if (config.features & kFeatureNormalizedDensity) density_factor_ = &store_.add<float>();
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
      if (density_factor_) density_factor_->data[i] = fresh_density_factor();
    }
    count_ = total;
    max_speed_valid_ = false;
    if (springs_ && n > 0 && first_id < link_from_)
      link_from_ = first_id;  // they link at their first substep
  }

  FrameReport step_frame(double frame_dt, const RuntimeParams& params) override {
    return step_scene_frame(frame_dt, params, SceneFrame{});
  }

  FrameReport step_scene_frame(double frame_dt, const RuntimeParams& params,
                               const SceneFrame& scene_in) override {
    FrameReport report;
    FluidConstants fluid = make_fluid_constants(config_, params);
    const StepLimits limits = make_step_limits(config_, params);
    SceneFrame scene = scene_in;
    bind_scene_views(scene, [](const SdfAsset& a) { return a.host_view(); });
    report.removed_by_sink.assign(scene.sinks.size(), 0u);
    const uint32_t count_before = count_;
    const auto saved = store_.snapshot();
    const float saved_max_speed = max_speed_;
    const bool saved_max_speed_valid = max_speed_valid_;
    const float saved_max_acceleration = max_acceleration_;
    const uint32_t saved_link_from = link_from_;
    spring_constants_ = fluid.methods.springs;
    if (!max_speed_valid_) max_speed_ = compute_max_speed();

    // Puts the particles back as they were before the frame: on a non-finite state and on any
    // exception (an allocation that fails halfway through a frame), so a failed step changes
    // nothing. The store's arrays keep their capacity, so this copies and does not allocate.
    auto roll_back = [&]() {
      count_ = count_before;
      store_.resize(count_);
      store_.restore(saved);
      max_speed_ = saved_max_speed;
      max_speed_valid_ = saved_max_speed_valid;
      max_acceleration_ = saved_max_acceleration;  // the force step limit reads it next step
      link_from_ = saved_link_from;
    };
    double remaining = frame_dt;
    double elapsed = 0.0;
    report.dt_min = std::numeric_limits<float>::max();
    try {
      while (remaining > 0.0 && report.substeps < params.stepping.max_substeps) {
        const float speed = std::max(max_speed_, scene.max_collider_speed);
        const double dt = landing_dt(controller_dt(limits, speed, max_acceleration_), remaining);
        const float dtf = static_cast<float>(dt);
        SubstepTime time;
        time.tau0 = static_cast<float>(elapsed);
        time.tau1 = static_cast<float>(elapsed + dt);
        time.s0 = static_cast<float>(elapsed / frame_dt);
        time.s1 = remaining <= dt ? 1.0f : static_cast<float>((elapsed + dt) / frame_dt);
        time.dt = dtf;
        fluid.dt = dtf;
        const uint32_t bad = config_.integrator == Integrator::Rk4
                                 ? substep_rk4(fluid, scene, time, report)
                                 : substep_euler(fluid, scene, time, report);
        if (bad != kAllFinite) {
          roll_back();
          throw Error(Status::NonFinite, "the step produced non-finite values in the " + non_finite_.where +
                                             " of substep " + std::to_string(report.substeps + 1) + " (dt " +
                                             std::to_string(dtf) + " s" + above_stable_step(dtf, limits) +
                                             "): " + non_finite_.particles +
                                             "; the world was restored to its state before sph_world_step");
        }
        if (!scene.sinks.empty()) apply_sinks(scene, report);
        remaining -= dt;
        elapsed += dt;
        ++report.substeps;
        report.time_advanced += dt;
        report.dt_min = std::min(report.dt_min, dtf);
        report.dt_max = std::max(report.dt_max, dtf);
      }
    } catch (const Error& e) {
      if (e.status() != Status::NonFinite) roll_back();  // NonFinite has rolled back already
      throw;
    } catch (...) {
      roll_back();
      throw;
    }
    if (report.substeps == 0) report.dt_min = 0.0f;
    report.completed = remaining <= 0.0;
    report.max_speed = max_speed_;
    const auto t = Clock::now();
    summarize(report);
    report.stage_ms[kStageOther] += static_cast<float>(elapsed_ms(t));
    return report;
  }

  void truncate(uint32_t count) override {
    if (count > count_) throw Error(Status::Internal, "truncate: beyond the particle count");
    count_ = count;
    store_.resize(count_);
    max_speed_valid_ = false;
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

  ParticleSnapshot export_particles() const override {
    ParticleSnapshot s;
    s.position.assign(position_.data.begin(), position_.data.begin() + count_);
    s.velocity.assign(velocity_.data.begin(), velocity_.data.begin() + count_);
    s.id.assign(id_.data.begin(), id_.data.begin() + count_);
    s.density.assign(density_.data.begin(), density_.data.begin() + count_);
    if (density_factor_)
      s.density_factor.assign(density_factor_->data.begin(), density_factor_->data.begin() + count_);
    // The lazily computed max speed is a pure function of the velocities: taking it now gives
    // the value the next frame would compute.
    s.max_speed = max_speed_valid_ ? max_speed_ : compute_max_speed();
    s.max_acceleration = max_acceleration_;
    if (springs_) {
      s.springs.assign(springs_->data.begin(), springs_->data.begin() + count_);
      s.link_from = link_from_;
    }
    return s;
  }

  void import_particles(const ParticleSnapshot& s) override {
    const uint32_t n = static_cast<uint32_t>(s.id.size());
    if (n > config_.capacity || s.position.size() != n || s.velocity.size() != n || s.density.size() != n)
      throw Error(Status::Internal, "import_particles: inconsistent snapshot");
    if (springs_ ? s.springs.size() != n : !s.springs.empty())
      throw Error(Status::Internal, "import_particles: spring lists do not match the particles");
    std::vector<SpringList> springs(s.springs);
    // Copies first (they may throw), then swaps, so a failure leaves the state as it was.
    std::vector<Float4> position(s.position), velocity(s.velocity);
    std::vector<uint32_t> id(s.id), neighbors(n, 0u);
    std::vector<float> density(s.density);
    std::vector<float> factor;
    if (density_factor_) {
      // A snapshot without factors (a checkpoint written before they existed) starts every
      // particle fresh, as if it had just been spawned.
      if (!s.density_factor.empty() && s.density_factor.size() != n)
        throw Error(Status::Internal, "import_particles: inconsistent snapshot");
      factor = s.density_factor.empty() ? std::vector<float>(n, fresh_density_factor()) : s.density_factor;
    }
    store_.resize(n);
    position_.data.swap(position);
    velocity_.data.swap(velocity);
    id_.data.swap(id);
    density_.data.swap(density);
    neighbors_.data.swap(neighbors);
    if (springs_) {
      springs_->data.swap(springs);
      link_from_ = s.link_from;
    }
    if (density_factor_) density_factor_->data.swap(factor);
    count_ = n;
    max_speed_ = s.max_speed;
    max_speed_valid_ = true;
    max_acceleration_ = s.max_acceleration;
  }

  uint64_t memory_bytes() const override { return store_.bytes() + grid_.bytes(); }

 private:
  static constexpr uint32_t kAllFinite = 0xffffffffu;

  // Threads for a loop over the particles: small worlds run on the calling thread alone, where
  // waking a team (and its spinning idle threads) would cost more than the work.
  unsigned threads() const { return count_ >= kParallelMinimum ? workers_ : 1u; }

  int n() const { return static_cast<int>(count_); }

  float compute_max_speed() const {
    float v2max = 0.0f;
#pragma omp parallel for num_threads(threads()) schedule(static) reduction(max : v2max)
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
    float* factor = density_factor_ ? density_factor_->data.data() : nullptr;
    if (factor) normalized_.resize(count_);
#pragma omp parallel for num_threads(threads()) schedule(static)
    for (int i = 0; i < n(); ++i) {
      const DensitySample s = gather_density(fluid, view, pos, static_cast<uint32_t>(i));
      float rho = s.density;
      if (factor) {
        normalized_[i] = s.density;  // the summation, for the factor after the filter
        rho = carried_density(fluid, s.density, factor[i]);
      }
      density_.data[i] = rho;
      neighbors_.data[i] = s.neighbor_count;
      // Only the w slots are written; neighbours read x, y, z alone.
      pos[i].w = pressure_from_density(fluid.methods.eos, rho);
      vel[i].w = 1.0f / rho;
    }
    if (factor) {
      // Eq. 31 over every carried rho_j: each particle writes only its own factor and side
      // slot (the first pass is done reading the factors), then the filtered values are published.
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i) {
        const float filtered = gather_normalized_density(fluid, view, pos, vel, static_cast<uint32_t>(i));
        factor[i] = filtered / normalized_[i];
        normalized_[i] = filtered;
      }
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i) {
        density_.data[i] = normalized_[i];
        pos[i].w = pressure_from_density(fluid.methods.eos, normalized_[i]);
        vel[i].w = 1.0f / normalized_[i];
      }
    }
    if (config_.features & kFeatureSurfaceTension) {
      // Colour-field normals of every particle, which the force gather reads for neighbours.
      normals_.resize(count_);
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i)
        normals_[i] = gather_colour_normal(fluid, view, pos, vel, static_cast<uint32_t>(i));
    }
    report.stage_ms[kStageDensity] += static_cast<float>(elapsed_ms(t));
  }

  // Acceleration of particle i: the neighbour gather with the world's force terms compiled in
  // (forces.h), plus the scene's force fields.
  template <class Terms>
  static Vec3 acceleration_with(const FluidConstants& fluid, const GridView& view, const ForceInputs& in,
                                const SceneFrame& scene, uint32_t i) {
    Vec3 a = gather_acceleration<Terms>(fluid, view, in, i);
    for (const ForceFieldFrame& f : scene.fields) a += force_field_acceleration(f.view, xyz(in.positions[i]));
    return a;
  }
  using AccelerationFn = Vec3 (*)(const FluidConstants&, const GridView&, const ForceInputs&,
                                  const SceneFrame&, uint32_t);
  AccelerationFn acceleration_function() const {
    return with_force_terms(config_.selection(),
                            [](auto terms) -> AccelerationFn { return &acceleration_with<decltype(terms)>; });
  }
  ForceInputs force_inputs() const {
    return ForceInputs{position_.data.data(), velocity_.data.data(), neighbors_.data.data(), normals_.data()};
  }

  // Resolves colliders for the state in next_position_/next_velocity_, moved from x_old(i).
  template <class OldPosition>
  void collide(const SceneFrame& scene, const SubstepTime& time, OldPosition&& x_old, FrameReport& report) {
    if (scene.colliders.empty()) return;
    const auto t = Clock::now();
    const float h = config_.kernel_radius;
#pragma omp parallel for num_threads(threads()) schedule(static)
    for (int i = 0; i < n(); ++i) {
      Vec3 x = xyz(next_position_[i]);
      Vec3 v = xyz(next_velocity_[i]);
      const Vec3 from = x_old(static_cast<uint32_t>(i));
      for (const ColliderFrame& c : scene.colliders) collide_particle(c.view, time, h, from, x, v);
      next_position_[i] = make_float4_record(x, next_position_[i].w);
      next_velocity_[i] = make_float4_record(v, next_velocity_[i].w);
    }
    report.stage_ms[kStageCollide] += static_cast<float>(elapsed_ms(t));
  }

  // Max speed and the first non-finite particle of the state in next_*.
  uint32_t scan_next_state(float& v2max) const {
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
  static std::string above_stable_step(float dt, const StepLimits& limits) {
    if (!(limits.stability_dt > 0.0f) || dt <= limits.stability_dt) return "";
    return ", above this world's stable step " + std::to_string(limits.stability_dt) +
           " s (0.4 h / c, 0.05 h^2 rho0 / mu), forced by dt_min";
  }

  // Where a failed substep went non-finite, worked out on the failure path only, before the new
  // state replaces the old: the particle with the lowest index names the stage (the first of
  // its density and pressure, its acceleration, its integrated state and the collision response
  // that is not finite; the CUDA backend names the same), and up to 8 ids are listed.
  void diagnose_non_finite(const FluidConstants& fluid, const SceneFrame& scene, int rk4_stage,
                           uint32_t first) {
    const Float4* pos = position_.data.data();
    const Float4* vel = velocity_.data.data();
    const uint32_t i = first;
    const char* stage = "collide stage (SPH_STAGE_COLLIDE)";
    if (!std::isfinite(density_.data[i]) || !std::isfinite(pos[i].w) || !std::isfinite(vel[i].w)) {
      stage = "density stage (SPH_STAGE_DENSITY)";
    } else {
      Vec3 a = acceleration_function()(fluid, grid_.view(), force_inputs(), scene, i);
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
    non_finite_.particles = std::to_string(count) + (count == 1 ? " particle, id " : " particles, ids ") +
                            ids + (count > 8 ? ", ..." : "");
  }

  uint32_t finish_substep(float v2max, uint32_t bad_index) {
    position_.data.swap(next_position_);
    velocity_.data.swap(next_velocity_);
    max_speed_ = std::sqrt(v2max);
    max_speed_valid_ = true;
    return bad_index == kAllFinite ? kAllFinite : id_.data[bad_index];
  }

  uint32_t substep_euler(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                         FrameReport& report) {
    sort_and_density(fluid, report);
    spring_pass(time.dt, true, report);
    auto t = Clock::now();
    const GridView view = grid_.view();
    next_position_.resize(count_);
    next_velocity_.resize(count_);
    const Float4* pos = position_.data.data();
    const Float4* vel = velocity_.data.data();
    const float dt = time.dt;
    const AccelerationFn acceleration = acceleration_function();
    const ForceInputs inputs = force_inputs();
    float a2max = 0.0f;
#pragma omp parallel for num_threads(threads()) schedule(static) reduction(max : a2max)
    for (int i = 0; i < n(); ++i) {
      Vec3 a = acceleration(fluid, view, inputs, scene, static_cast<uint32_t>(i));
      if (springs_) a += spring_acceleration_[i];
      a2max = std::max(a2max, length_squared(a));
      const ParticleState s = symplectic_euler({xyz(pos[i]), xyz(vel[i])}, a, dt);
      next_position_[i] = make_float4_record(s.position, pos[i].w);
      next_velocity_[i] = make_float4_record(s.velocity, vel[i].w);
    }
    max_acceleration_ = std::sqrt(a2max);
    report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
    collide(
        scene, time, [&](uint32_t i) { return xyz(pos[i]); }, report);
    t = Clock::now();
    float v2max = 0.0f;
    const uint32_t bad_index = scan_next_state(v2max);
    if (bad_index != kAllFinite) diagnose_non_finite(fluid, scene, -1, bad_index);
    const uint32_t bad = finish_substep(v2max, bad_index);
    report.stage_ms[kStageIntegrate] += static_cast<float>(elapsed_ms(t));
    return bad;
  }

  uint32_t substep_rk4(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                       FrameReport& report) {
    // Stage 0 starts from the current state.
    for (int i = 0; i < n(); ++i)
      rk4_start_->data[i] = ParticleState{xyz(position_.data[i]), xyz(velocity_.data[i])};
    const float dt = time.dt;
    const AccelerationFn acceleration = acceleration_function();
    float a2max = 0.0f;
    for (int stage = 0; stage < 4; ++stage) {
      sort_and_density(fluid, report);
      spring_pass(dt, stage == 0, report);
      auto t = Clock::now();
      const GridView view = grid_.view();
      next_position_.resize(count_);
      next_velocity_.resize(count_);
      const Float4* pos = position_.data.data();
      const Float4* vel = velocity_.data.data();
      const ForceInputs inputs = force_inputs();
#pragma omp parallel for num_threads(threads()) schedule(static) reduction(max : a2max)
      for (int i = 0; i < n(); ++i) {
        Vec3 a = acceleration(fluid, view, inputs, scene, static_cast<uint32_t>(i));
        if (springs_) a += spring_acceleration_[i];
        a2max = std::max(a2max, length_squared(a));
        const ParticleState s =
            rk4_advance(stage, rk4_start_->data[i], {xyz(pos[i]), xyz(vel[i])}, a, dt, rk4_sum_->data[i]);
        next_position_[i] = make_float4_record(s.position, pos[i].w);
        next_velocity_[i] = make_float4_record(s.velocity, vel[i].w);
      }
      report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
      if (stage == 3)
        collide(
            scene, time, [&](uint32_t i) { return rk4_start_->data[i].position; }, report);
      t = Clock::now();
      float v2max = 0.0f;
      const uint32_t bad_index = scan_next_state(v2max);
      if (bad_index != kAllFinite) diagnose_non_finite(fluid, scene, stage, bad_index);
      const uint32_t bad = finish_substep(v2max, bad_index);
      report.stage_ms[kStageIntegrate] += static_cast<float>(elapsed_ms(t));
      if (bad != kAllFinite) return bad;
    }
    max_acceleration_ = std::sqrt(a2max);
    return kAllFinite;
  }

  // Springs (SPH_FEATURE_SPRINGS), after the sort: the particles that wait for springs make
  // them (two passes, springs.h), then every particle gathers its spring acceleration into a
  // side array that the force pass adds. first_evaluation: the substep's first force
  // evaluation, where the rest lengths flow (plasticity).
  void spring_pass(float dt, bool first_evaluation, FrameReport& report) {
    if (!springs_) return;
    const auto t = Clock::now();
    const Float4* pos = position_.data.data();
    const Float4* vel = velocity_.data.data();
    SpringList* lists = springs_->data.data();
    const SpringConstants& c = spring_constants_;
    if (link_from_ != kNoPendingLinks) {
      const GridView view = grid_.view();
      const uint32_t* ids = id_.data.data();
      const uint32_t from = link_from_;
      spring_candidates_.resize(static_cast<size_t>(count_) * kSpringSlots);
      uint32_t* candidates = spring_candidates_.data();
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i)
        spring_candidates(c, view, pos, ids, from, lists[i], static_cast<uint32_t>(i),
                          candidates + static_cast<size_t>(i) * kSpringSlots);
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i) spring_link(pos, candidates, static_cast<uint32_t>(i), lists[i]);
      link_from_ = kNoPendingLinks;
    }
    spring_acceleration_.resize(count_);
    Vec3* out = spring_acceleration_.data();
    if (first_evaluation) {
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i)
        out[i] = spring_acceleration<true>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt);
    } else {
#pragma omp parallel for num_threads(threads()) schedule(static)
      for (int i = 0; i < n(); ++i)
        out[i] = spring_acceleration<false>(c, pos, vel, static_cast<uint32_t>(i), lists[i], dt);
    }
    report.stage_ms[kStageForces] += static_cast<float>(elapsed_ms(t));
  }

  // Removes particles inside any sink, keeping the order of the rest; records their ids.
  void apply_sinks(const SceneFrame& scene, FrameReport& report) {
    const auto t = Clock::now();
    keep_order_.clear();
    for (uint32_t i = 0; i < count_; ++i) {
      const Vec3 x = xyz(position_.data[i]);
      bool removed = false;
      for (size_t s = 0; s < scene.sinks.size() && !removed; ++s)
        if (sink_removes(scene.sinks[s].view, x)) {
          removed = true;
          ++report.removed_by_sink[s];
          report.removed_ids.push_back(id_.data[i]);
        }
      if (!removed) keep_order_.push_back(i);
    }
    if (keep_order_.size() != count_) {
      store_.permute(keep_order_.data(), keep_order_.size());
      count_ = static_cast<uint32_t>(keep_order_.size());
      store_.resize(count_);
    }
    report.stage_ms[kStageEmit] += static_cast<float>(elapsed_ms(t));
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
  HostArray<float>* density_factor_ = nullptr;  // normalised density's carried factor, when on
  // Integration writes here and swaps, so the force gather reads a state nobody writes.
  std::vector<Float4> next_position_;
  std::vector<Float4> next_velocity_;
  std::vector<uint32_t> keep_order_;
  std::vector<float> normalized_;  // normalised density: the summation, then eq. 31 (side array)
  std::vector<Float4> normals_;    // colour-field normals, when surface tension is on
  // Springs (SPH_FEATURE_SPRINGS only): the lists live in the store; the link candidates
  // and the spring accelerations of the current evaluation are side arrays.
  HostSpringArray* springs_ = nullptr;
  std::vector<uint32_t> spring_candidates_;
  std::vector<Vec3> spring_acceleration_;
  SpringConstants spring_constants_{};
  uint32_t link_from_ = kNoPendingLinks;  // lowest id that waits for its springs
  uint32_t count_ = 0;
  float max_speed_ = 0.0f;
  float max_acceleration_ = 0.0f;  // of the last force evaluation, for the force step limit
  struct {
    std::string where;      // the stage of the first non-finite particle
    std::string particles;  // how many, and their ids
  } non_finite_;            // of the last failed substep, for its error message
  bool max_speed_valid_ = false;
};

}  // namespace

std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count) {
  return std::make_unique<CpuBackend>(config, worker_count);
}

}  // namespace sph
