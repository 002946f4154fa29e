// SPDX-License-Identifier: MIT
// The world's probes and gauges: their checks, their sample points in a frame, and their
// readings of the last step (the sampling itself is physics/probe_sampling.h, run by the
// backends inside the substep).
#include <cmath>
#include <string>

#include "field_checks.h"
#include "field_error.h"
#include "position_reach.h"
#include "status.h"
#include "world.h"

namespace sph {
namespace {

constexpr size_t kMaxProbes = 65536;

// The particles' reach (position_reach.h): far points would only ever read air.
void require_resolved(const Vec3& p, float spacing, const char* field) {
  if (resolution_problem(p, spacing).empty()) return;
  throw FieldError(Status::InvalidArgument, field,
                   "lies farther than " + describe_value(kMaxPositionInSpacings * spacing) +
                       " m (65536 particle spacings) from the origin, where no particle may be");
}

// |v| in double: a float's square underflows below about 1e-19 (a direction of (1e-30, 0, 0)
// would read as none) and overflows above about 1e19.
double exact_length(const Vec3& v) {
  const double x = v.x, y = v.y, z = v.z;
  return std::sqrt(x * x + y * y + z * z);
}

// v / |v|, or zero for the zero vector.
Vec3 unit_or_zero(const Vec3& v) {
  const double n = exact_length(v);
  if (!(n > 0.0)) return Vec3{0.0f, 0.0f, 0.0f};
  return Vec3{static_cast<float>(v.x / n), static_cast<float>(v.y / n), static_cast<float>(v.z / n)};
}

// The gauge's direction, or the world's up (against gravity; +y without gravity).
Vec3 gauge_axis(const Probe& p, const Vec3& gravity) {
  const Vec3 d = unit_or_zero(exact_length(p.direction) > 0.0 ? p.direction : gravity * -1.0f);
  return exact_length(d) > 0.0 ? d : Vec3{0.0f, 1.0f, 0.0f};
}

}  // namespace

uint64_t World::add_probe(const ProbeSpec& spec) {
  require_finite_vec3_field(spec.position, "position");
  require_resolved(spec.position, config_.particle_spacing, "position");
  Probe p;
  p.gauge = spec.gauge;
  p.every_substep = spec.every_substep;
  p.position = spec.position;
  if (spec.gauge) {
    require_finite_vec3_field(spec.direction, "direction");
    require_finite_field(spec.length, "length");
    if (!(spec.length > 0.0f))
      throw FieldError(Status::InvalidArgument, "length",
                       "a gauge's length must be > 0, got " + describe_value(spec.length));
    require_non_negative_field(spec.sample_spacing, "sample_spacing");
    const float spacing = spec.sample_spacing > 0.0f ? spec.sample_spacing : config_.kernel_radius / 8.0f;
    const double steps = std::ceil(static_cast<double>(spec.length) / static_cast<double>(spacing));
    if (!(steps <= static_cast<double>(kMaxGaugeSamples)))
      throw FieldError(Status::InvalidArgument, "sample_spacing",
                       "gives " + describe_value(static_cast<float>(steps)) +
                           " steps along the gauge's length " + describe_value(spec.length) +
                           " m; at most 65536 (raise sample_spacing)");
    // The far end, whichever way gravity points later.
    const float reach = spec.length;
    require_resolved(Vec3{std::fabs(spec.position.x) + reach, std::fabs(spec.position.y) + reach,
                          std::fabs(spec.position.z) + reach},
                     config_.particle_spacing, "length");
    // Normalised in double: any finite non-zero direction is a direction, however short or long.
    p.direction = unit_or_zero(spec.direction);
    p.length = spec.length;
    p.sample_count = steps < 1.0 ? 1u : static_cast<uint32_t>(steps);
  }
  if (probes_.size() >= kMaxProbes) throw Error(Status::Capacity, "a world holds at most 65536 probes");
  const uint64_t points = probe_points_ + p.points();
  if (points > kMaxProbePoints)
    throw Error(Status::Capacity, "the world's probes would sample " + std::to_string(points) +
                                      " points a step; at most " + std::to_string(kMaxProbePoints) +
                                      " (a point probe samples one, a gauge length / sample_spacing)");
  const uint64_t id = probes_.insert(std::move(p));
  probe_points_ = points;
  return id;
}

void World::remove_probe(uint64_t id) {
  if (id == 0) return;
  const Probe* p = probes_.find(id);
  if (!p) throw Error(Status::InvalidHandle, "id: is stale or not of this world");
  const uint32_t points = p->points();
  probes_.erase(id);
  probe_points_ -= points;
}

void World::set_probe_pressure_threshold(uint64_t id, float threshold) {
  Probe& p = probes_.at(id);
  require_non_negative_field(threshold, "pressure");
  p.pressure_threshold = threshold;
}

void World::adopt_probes(const World& from) {
  SlotMap<Probe> probes = from.probes_;
  probes.for_each([](uint64_t, Probe& p) { p.reading = ProbeReading{}; });
  probes_ = std::move(probes);
  probe_points_ = from.probe_points_;
}

void World::restore_probes(SlotTable<Probe> table) {
  probes_.restore(std::move(table));
  probe_points_ = 0;
  probes_.for_each([&](uint64_t, const Probe& p) { probe_points_ += p.points(); });
}

const Probe& World::probe(uint64_t id) const { return probes_.at(id); }

void World::add_probe_frames(SceneFrame& scene) const {
  scene.probes.reserve(probes_.size());
  uint32_t points = 0;  // at most kMaxProbePoints (add_probe, the checkpoint reader)
  probes_.for_each([&](uint64_t, const Probe& p) {
    ProbeView v;
    v.origin = p.position;
    v.step = Vec3{0.0f, 0.0f, 0.0f};
    if (p.gauge)
      v.step = gauge_axis(p, params_.stepping.gravity) * (p.length / static_cast<float>(p.sample_count));
    v.first_point = points;
    v.point_count = p.points();
    v.gauge = p.gauge ? 1u : 0u;
    v.every_substep = p.every_substep ? 1u : 0u;
    points += v.point_count;
    scene.probes.push_back(v);
  });
  scene.probe_points = points;
}

// The frame's sums as readings (a probe added after the step's scene was built has none yet).
void World::store_probe_readings(const FrameReport& report) {
  probes_.for_each([&, index = size_t{0}](uint64_t, Probe& p) mutable {
    ProbeReading r;
    if (index < report.probes.size()) {
      const ProbeSums& s = report.probes[index];
      const double inv = s.time > 0.0 ? 1.0 / s.time : 0.0;
      r.samples = s.samples;
      r.density = static_cast<float>(s.density * inv);
      r.pressure = static_cast<float>(s.pressure * inv);
      r.velocity = Vec3{static_cast<float>(s.velocity[0] * inv), static_cast<float>(s.velocity[1] * inv),
                        static_cast<float>(s.velocity[2] * inv)};
      r.kernel_sum = static_cast<float>(s.kernel_sum * inv);
      r.water_height = static_cast<float>(s.water_height * inv);
      r.pressure_max = s.samples > 0 ? s.pressure_max : 0.0f;
      r.time = s.time;
    }
    p.reading = r;
    ++index;
  });
}

}  // namespace sph
