// SPDX-License-Identifier: MIT
#include "world.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "point_clearance.h"
#include "rank_agreement.h"
#include "rank_transport.h"
#include "status.h"

namespace sph {
namespace {

Eigen::Quaterniond to_eigen(const Quat& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }

// A continuous source with a rate: the one whose emission a budget of particles limits.
bool rate_limited(const Source& s) { return s.mode == SourceMode::Continuous && s.rate > 0.0f; }

// Angular velocity (world frame) that turns `from` into `to` in `seconds`.
Vec3 angular_velocity(const Quat& from, const Quat& to, double seconds) {
  Eigen::Quaterniond delta = to_eigen(to) * to_eigen(from).conjugate();
  if (delta.w() < 0.0) delta.coeffs() = -delta.coeffs();  // the shorter arc
  const Eigen::AngleAxisd aa(delta.normalized());
  const Eigen::Vector3d w = aa.axis() * (aa.angle() / seconds);
  return Vec3{static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
}

bool same_pose(const RigidTransform& a, const RigidTransform& b) {
  return a.position.x == b.position.x && a.position.y == b.position.y && a.position.z == b.position.z &&
         a.rotation.x == b.rotation.x && a.rotation.y == b.rotation.y && a.rotation.z == b.rotation.z &&
         a.rotation.w == b.rotation.w;
}

// Largest distance from the asset's local origin to a corner of its grid.
float bounding_radius(const SdfAsset& a) {
  float r = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const Vec3 idx{(c & 1) ? static_cast<float>(a.nx() - 1) : 0.0f,
                   (c & 2) ? static_cast<float>(a.ny() - 1) : 0.0f,
                   (c & 4) ? static_cast<float>(a.nz() - 1) : 0.0f};
    r = std::max(r, length(apply_affine(a.index_to_local(), idx)));
  }
  return r;
}

float max_field_speed(const SdfAsset& a) {
  float v2 = 0.0f;
  for (const Vec3& v : a.velocity()) v2 = std::max(v2, length_squared(v));
  return std::sqrt(v2);
}

}  // namespace

World::World(const WorldConfig& config, std::unique_ptr<Backend> backend)
    : config_(config), backend_(std::move(backend)) {
  config_.max_capacity = std::max(config_.max_capacity, config_.capacity);  // 0: a fixed world
}

std::string World::capacity_limit() const {
  std::string text = "the world's max_capacity " + std::to_string(config_.max_capacity);
  if (config_.max_capacity == config_.capacity && config_.capacity < kMaxWorldCapacity)
    text += " (a fixed world: a larger sph_world_def.max_capacity lets it grow)";
  return text;
}

bool World::reserve_particles(uint64_t total) {
  if (total <= config_.capacity) return false;
  if (total > config_.max_capacity)
    throw Error(Status::Capacity, std::to_string(total) + " particles do not fit in " + capacity_limit());
  const uint64_t doubled = 2ull * config_.capacity;
  const uint32_t grown =
      static_cast<uint32_t>(std::min<uint64_t>(std::max(total, doubled), config_.max_capacity));
  Backend::GrowthNeeds needs;
  needs.sinks = sinks_.size() != 0;
  if (config_.features & kFeatureColliderLoads)
    needs.load_colliders = static_cast<uint32_t>(colliders_.size());
  backend_->reserve(grown, needs);  // all-or-nothing
  config_.capacity = grown;
  ++capacity_growths_;
  return true;
}

uint32_t World::spawn(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities,
                      uint32_t user_attribute) {
  const uint64_t n = positions.size();
  if (backend_->distributed() && !rank_add_)
    throw Error(Status::Unsupported,
                "world: it is distributed over MPI ranks (sph_mpi.h): add its particles with "
                "sph_mpi_world_add_particles, which numbers them across the ranks (the fills do not work "
                "distributed: fill an undivided world and add its particles; sources do)");
  if (static_cast<uint64_t>(next_id_) + n > UINT32_MAX)
    throw Error(Status::Capacity, "spawn: the world has used up its 2^32 particle ids");
  const uint32_t first = next_id_;
  if (n == 0) return first;
  // Grown before the append: a failed append leaves the larger storage, which holds the same
  // particles (growth changes no particle, and capacity never shrinks).
  try {
    reserve_particles(particle_count() + n);
  } catch (const Error& e) {
    throw Error(e.status(), "spawn: " + std::string(e.what()) + "; the world holds " +
                                std::to_string(particle_count()) + " of its capacity " +
                                std::to_string(config_.capacity));
  }
  backend_->append(positions.data(), velocities ? velocities->data() : nullptr, static_cast<uint32_t>(n),
                   first, user_attribute);
  next_id_ += static_cast<uint32_t>(n);
  return first;
}

void World::emit_sources(double frame_dt) {
  HostVector<Vec3> existing;
  bool have_existing = false;
  const bool distributed = backend_->distributed();
  sources_.for_each([&](uint64_t id, Source& s) {
    if (s.mode == SourceMode::FillOnce && s.done) return;
    if (!have_existing) {
      existing.resize(particle_count());
      if (!existing.empty())
        backend_->copy_attribute(AttributeKind::Position, 0, particle_count(), existing.data(), sizeof(Vec3));
      have_existing = true;
    }
    const SdfGridView region = s.region->host_view();
    HostVector<Vec3> points(s.lattice.size());
    for (size_t i = 0; i < points.size(); ++i) points[i] = to_world(s.pose, s.lattice[i]);
    HostVector<char> keep = clear_of_points(existing, points, s.min_distance);
    if (distributed) agree_clear_points(keep);
    HostVector<Vec3> accepted, velocities;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!keep[i]) continue;
      accepted.push_back(points[i]);
      velocities.push_back(s.velocity_from_field
                               ? direction_to_world(s.pose, sample_velocity(region, s.lattice[i]))
                               : s.velocity);
    }
    size_t allowed = accepted.size();
    if (rate_limited(s)) {
      s.rate_budget += static_cast<double>(s.rate) * frame_dt;
      // (compared in double: a budget past the size_t range must not be cast to it)
      if (s.rate_budget < static_cast<double>(allowed))
        allowed = s.rate_budget > 0.0 ? static_cast<size_t>(s.rate_budget) : 0;  // a debt emits none
    }
    // A world numbers its particles with 32-bit ids and never reuses one (spawn); once they run
    // out a source emits what is left and reports the rest, as at a full capacity.
    const size_t ids_left = UINT32_MAX - next_id_;
    HostVector<char> mine;
    if (distributed) mine = points_of_this_rank(accepted);
    const size_t fits = distributed ? rank_emission_fits(mine, std::min(allowed, ids_left))
                                    : std::min<size_t>({allowed, room(), ids_left});
    if (fits < allowed)
      events_.push_back(Event{EventType::SourceCapacityReached, id, static_cast<uint32_t>(allowed - fits)});
    accepted.resize(fits);
    velocities.resize(fits);
    mine.resize(distributed ? fits : 0);
    const size_t kept = distributed ? static_cast<size_t>(std::count(mine.begin(), mine.end(), 1)) : fits;
    if (reserve_particles(static_cast<uint64_t>(particle_count()) + kept))
      events_.push_back(Event{EventType::CapacityGrown, id, config_.capacity});
    if (rate_limited(s)) {
      // What the region or the world could not take stays owed, but at most one region's worth:
      // "at most rate particles/s" holds over any window once the backlog is out (unbounded, a
      // region held full for a minute then refilled whole every frame for a minute), and the
      // budget stays within what a checkpoint carries (it outgrew 1e15 at high rates).
      s.rate_budget =
          std::min(s.rate_budget - static_cast<double>(fits), static_cast<double>(s.lattice.size()));
    }
    if (distributed) {
      emit_on_ranks(accepted, velocities, mine, s.user_attribute, existing);
    } else if (!accepted.empty()) {
      spawn(accepted, &velocities, s.user_attribute);
      existing.insert(existing.end(), accepted.begin(), accepted.end());
    }
    s.done = true;
  });
}

void World::prepare() {
  // The frame's length only sets the colliders' velocities, which nothing prepared depends on.
  const SceneFrame scene = build_scene_frame(1.0);
  backend_->prepare_scene(scene, params_);
}

SceneFrame World::build_scene_frame(double frame_dt) const {
  SceneFrame scene;
  colliders_.for_each([&](uint64_t, const Collider& c) {
    ColliderFrame f;
    f.sdf = c.sdf;
    ColliderView& v = f.view;
    v.pose_start = c.pose;
    v.pose_end = c.target ? *c.target : c.pose;
    v.moving = same_pose(v.pose_start, v.pose_end) ? 0u : 1u;
    v.linear_velocity = (v.pose_end.position - v.pose_start.position) * static_cast<float>(1.0 / frame_dt);
    v.angular_velocity = v.moving ? angular_velocity(v.pose_start.rotation, v.pose_end.rotation, frame_dt)
                                  : Vec3{0.0f, 0.0f, 0.0f};
    v.restitution = c.material.restitution;
    v.friction = c.material.friction;
    v.stickiness = c.material.stickiness;
    v.sign = c.inverted ? -1.0f : 1.0f;
    v.deforming = c.sdf->has_moving_surface() ? 1u : 0u;
    v.boundary_map = nullptr;  // the backend binds its map (SPH_FEATURE_BOUNDARY_DENSITY)
    v.load_point = c.load_point;
    float speed = 0.0f;
    if (v.moving) speed += length(v.linear_velocity) + length(v.angular_velocity) * bounding_radius(*c.sdf);
    if (v.deforming) speed += max_field_speed(*c.sdf);
    scene.max_collider_speed = std::max(scene.max_collider_speed, speed);
    scene.colliders.push_back(std::move(f));
  });
  force_fields_.for_each([&](uint64_t, const ForceField& f) {
    ForceFieldFrame frame;
    frame.region = f.region;
    frame.grid = f.grid;
    ForceFieldView& v = frame.view;
    v = ForceFieldView{};
    v.kind = f.kind;
    v.has_region = f.region ? 1u : 0u;
    v.pose = f.pose;
    v.vector = f.vector;
    v.strength = f.strength;
    v.falloff_radius = f.falloff_radius;
    scene.fields.push_back(std::move(frame));
  });
  sinks_.for_each([&](uint64_t id, const Sink& s) {
    SinkFrame frame;
    frame.id = id;
    frame.region = s.region;
    frame.view = SinkView{};
    frame.view.mode = s.mode;
    frame.view.pose = s.pose;
    frame.view.bounds_min = s.bounds_min;
    frame.view.bounds_max = s.bounds_max;
    scene.sinks.push_back(std::move(frame));
  });
  add_probe_frames(scene);
  return scene;
}

namespace {
// A threshold event's count: the magnitude rounded down, saturated at the largest count.
uint32_t event_magnitude(float value) {
  return value >= 4294967040.0f ? UINT32_MAX : static_cast<uint32_t>(value);
}

// A frame's impulses as time averages (zero for a frame that advanced no time).
ColliderLoadResult load_result(const ColliderLoadSums& sums, const Collider& c, const FrameReport& report) {
  ColliderLoadResult r;
  const double inv_t = report.time_advanced > 0.0 ? 1.0 / report.time_advanced : 0.0;
  r.force = Vec3{static_cast<float>(sums.linear[0] * inv_t), static_cast<float>(sums.linear[1] * inv_t),
                 static_cast<float>(sums.linear[2] * inv_t)};
  r.torque = Vec3{static_cast<float>(sums.angular[0] * inv_t), static_cast<float>(sums.angular[1] * inv_t),
                  static_cast<float>(sums.angular[2] * inv_t)};
  r.point = to_world(c.pose, c.load_point);  // c.pose is the end of the frame's pose here
  r.time = report.time_advanced;
  return r;
}
}  // namespace

bool World::step(double frame_dt, const StepInterrupt& interrupt, const FrameEnqueuedHook& enqueued) {
  const auto start = std::chrono::steady_clock::now();
  bool stop_now = interrupt.requested();
  // A distributed world's ranks decide together: a rank that returned here alone would leave
  // the others waiting in the frame's first collective call.
  if (const RankTransport* ranks = backend_->rank_transport()) {
    int64_t none_asked = stop_now ? 0 : 1;
    agree(*ranks, &none_asked);
    stop_now = none_asked == 0;
  }
  if (stop_now) {
    report_ = FrameReport{};
    report_.completed = false;
    report_.interrupted = true;
    events_.clear();
    last_step_ms_ = 0.0f;
    return false;
  }
  // Everything a failed step must put back.
  const uint32_t count_before = particle_count();
  const uint32_t next_id_before = next_id_;
  struct SourceState {
    uint64_t id;
    bool done;
    double rate_budget;
  };
  HostVector<SourceState> sources_before;
  sources_.for_each([&](uint64_t id, const Source& s) {
    sources_before.push_back({id, s.done, s.rate_budget});
  });
  // The last step's events, kept aside (no allocation: nothing can fail from here to the try).
  HostVector<Event> events_before;
  events_before.swap(events_);
  FrameReport report;
  try {
    // Reserved up front, so that nothing after the backend's frame can fail on an allocation:
    // once the particles have moved, the rest of the step must not throw.
    // + each source's growth + the solves' capped events + the colliders' and probes' thresholds
    events_.reserve(2 * sources_.size() + sinks_.size() + 2 + colliders_.size() + probes_.size());
    SceneFrame scene = build_scene_frame(frame_dt);
    if (sources_.size() > 0) {
      backend_->prepare_scene(scene, params_);  // before emission can grow the world
      backend_->save_step_inputs();
    }
    emit_sources(frame_dt);
    scene.interrupt = interrupt;
    scene.enqueued = enqueued;
    report = backend_->step_scene_frame(frame_dt, params_, scene);
  } catch (...) {
    if (particle_count() > count_before) {
      backend_->truncate(count_before);
      backend_->restore_step_inputs();
    }
    next_id_ = next_id_before;
    for (const SourceState& saved : sources_before) {
      Source* s = sources_.find(saved.id);
      s->done = saved.done;
      s->rate_budget = saved.rate_budget;
    }
    events_.swap(events_before);
    // (A distributed world's other ranks fail too, rather than wait for this one.)
    backend_->rethrow_step_failure();
    throw;
  }
  // A frame that stopped early gives back the rate credit of the time it did not simulate: the
  // sources emitted at its start as if it would run whole, so the budget may become a debt that
  // later frames pay first ("at most rate particles per second" of simulated time).
  if (!report.completed)
    sources_.for_each([&](uint64_t, Source& s) {
      if (!rate_limited(s)) return;
      const double unsimulated = std::max(frame_dt - report.time_advanced, 0.0);
      s.rate_budget = std::max(s.rate_budget - static_cast<double>(s.rate) * unsimulated, -kMaxSourceDebt);
    });
  // Colliders arrive where they were sent; their loads are the frame's impulses over its time.
  // A frame that stopped early (max_substeps, the budget, a cancel) leaves each moving collider
  // where its last whole substep placed it, the pose interpolated to the time reached (the
  // substeps' own fraction, substep_clock.h), and its target pending: the next step moves it
  // the rest of the way.
  const float reached = static_cast<float>(report.time_advanced / frame_dt);
  colliders_.for_each([&, index = size_t{0}](uint64_t id, Collider& c) mutable {
    if (c.target && report.completed) {
      c.pose = *c.target;
      c.target.reset();
    } else if (c.target && report.substeps > 0) {
      c.pose = interpolate(c.pose, *c.target, reached);
    }
    if (index < report.collider_loads.size()) {
      c.loads = load_result(report.collider_loads[index], c, report);
      const float force = length(c.loads.force);
      if (c.load_threshold > 0.0f && force >= c.load_threshold)
        events_.push_back(Event{EventType::ColliderLoadExceeded, id, event_magnitude(force)});
    }
    ++index;
  });
  store_probe_readings(report);
  probes_.for_each([&](uint64_t id, const Probe& p) {
    if (p.pressure_threshold > 0.0f && p.reading.samples > 0 &&
        p.reading.pressure_max >= p.pressure_threshold)
      events_.push_back(Event{EventType::ProbePressureExceeded, id, event_magnitude(p.reading.pressure_max)});
  });
  sinks_.for_each([&, index = size_t{0}](uint64_t id, const Sink&) mutable {
    const uint32_t removed = index < report.removed_by_sink.size() ? report.removed_by_sink[index] : 0u;
    if (removed > 0) events_.push_back(Event{EventType::SinkRemoved, id, removed});
    ++index;
  });
  // A DFSPH solve that stopped at its cap is never silent.
  if (report.pressure_solve.capped > 0)
    events_.push_back(Event{EventType::PressureSolveCapped, 0, report.pressure_solve.capped});
  if (report.divergence_solve.capped > 0)
    events_.push_back(Event{EventType::DivergenceSolveCapped, 0, report.divergence_solve.capped});
  report_ = std::move(report);
  simulated_time_ += report_.time_advanced;
  last_step_ms_ = static_cast<float>(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return report_.completed;
}

}  // namespace sph
