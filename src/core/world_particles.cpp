// SPDX-License-Identifier: MIT
// The world's entry points for particles from callers: spawns and lattice fills, validated
// whole before anything is added.
#include <algorithm>
#include <cmath>
#include <string>

#include "fcc_lattice.h"
#include "field_checks.h"
#include "position_reach.h"
#include "world.h"

namespace sph {

std::string World::position_problem(const Vec3& p, bool check_reach) const {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return "is not finite";
  return check_reach ? resolution_problem(p, config_.particle_spacing) : std::string();
}

void World::require_room_for_particles(uint64_t count) const {
  if (count > room())
    throw FieldError(Status::Capacity, "count",
                     std::to_string(count) + " particles do not fit; " + std::to_string(room()) + " of " +
                         capacity_limit() + " are free");
}

uint32_t World::add_particles(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities) {
  require_room_for_particles(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const std::string field = "positions[" + std::to_string(i) + "]";
    const Vec3& p = positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw FieldError(Status::InvalidArgument, field, "is not finite");
    const std::string problem = resolution_problem(p, config_.particle_spacing);
    if (!problem.empty()) throw FieldError(Status::InvalidArgument, field, problem);
  }
  if (velocities) {
    if (velocities->size() != positions.size())
      throw Error(Status::Internal, "add_particles: velocities and positions differ in count");
    for (size_t i = 0; i < velocities->size(); ++i) {
      const Vec3& v = (*velocities)[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw FieldError(Status::InvalidArgument, "velocities[" + std::to_string(i) + "]", "is not finite");
      require_particle_velocity_field(v, "velocities[" + std::to_string(i) + "]");
    }
  }
  return spawn(positions, velocities);
}

uint32_t World::add_rank_particles(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities,
                                   uint32_t first_id, uint32_t next_id_after) {
  if (!backend_->distributed())
    throw Error(Status::Internal, "add_rank_particles: the world is not distributed");
  const uint32_t next_id_before = next_id_;
  // undo_rank_particles puts them back: an append lowers the springs' lowest waiting id and a
  // truncation recomputes the max speed, so without them an undone add would leave other bytes.
  backend_->save_step_inputs();
  next_id_ = first_id;
  rank_add_ = true;
  try {
    add_particles(positions, velocities);
  } catch (...) {
    next_id_ = next_id_before;
    rank_add_ = false;
    throw;
  }
  rank_add_ = false;
  next_id_ = next_id_after;
  return first_id;
}

void World::undo_rank_particles(uint32_t count_before, uint32_t next_id_before) {
  if (particle_count() > count_before) {
    backend_->truncate(count_before);
    backend_->restore_step_inputs();  // saved by add_rank_particles
  }
  next_id_ = next_id_before;
}

namespace {

void require_fill_fits(uint64_t count, uint32_t free, const std::string& limit) {
  if (count > free)
    throw Error(Status::Capacity, "the fill makes " + std::to_string(count) + " particles but only " +
                                      std::to_string(free) + " of " + limit + " are free");
}

}  // namespace

uint32_t World::fill_box(const FillBoxSpec& spec) {
  require_finite_vec3_field(spec.min, "min");
  require_finite_vec3_field(spec.max, "max");
  require_particle_velocity_field(spec.velocity, "velocity");
  if (!(spec.max.x >= spec.min.x && spec.max.y >= spec.min.y && spec.max.z >= spec.min.z))
    throw FieldError(Status::InvalidArgument, "max", "every component must be >= min's");
  const float s = config_.particle_spacing;
  require_fill_fits(fcc_box_point_count(spec.min, spec.max, s), room(), capacity_limit());
  const HostVector<Vec3> points = fcc_points_in_box(spec.min, spec.max, s);
  return fill(points, spec.velocity, "min/max");
}

uint32_t World::fill_sphere(const FillSphereSpec& spec) {
  require_finite_vec3_field(spec.center, "center");
  require_non_negative_field(spec.radius, "radius");
  require_particle_velocity_field(spec.velocity, "velocity");
  if (spec.radius == 0.0f) return 0;  // a zeroed desc: an empty sphere
  const float s = config_.particle_spacing;
  // Refuse before generating anything when the lattice cannot possibly fit (the estimate
  // is within a few percent of the exact count for any sphere larger than a few spacings).
  const double estimate = fcc_sphere_point_estimate(spec.radius, s);
  if (estimate > 2.0 * room() + 4096.0)
    require_fill_fits(static_cast<uint64_t>(std::min(estimate, 1.8e19)), room(), capacity_limit());
  return fill(fcc_points_in_sphere(spec.center, spec.radius, s), spec.velocity, "center/radius");
}

uint32_t World::fill(const HostVector<Vec3>& points, const Vec3& velocity, const char* region_fields) {
  require_fill_fits(points.size(), room(), capacity_limit());
  for (const Vec3& p : points) {
    const std::string problem = resolution_problem(p, config_.particle_spacing);
    if (!problem.empty())
      throw FieldError(Status::InvalidArgument, region_fields, "a lattice point " + problem);
  }
  const HostVector<Vec3> velocities(points.size(), velocity);
  spawn(points, &velocities);
  return static_cast<uint32_t>(points.size());
}

}  // namespace sph
