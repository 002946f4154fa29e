// SPDX-License-Identifier: MIT
#include "pose_rules.h"

#include <cmath>

#include "field_checks.h"

namespace sph {
namespace {

// How far from 1 a stored unit quaternion's squared length may be: far above float rounding
// (a few 1e-7), far below any rotation a caller meant to be different.
constexpr double kUnitTolerance = 1e-3;

// A caller's quaternion or axis whose squared length is this close to 1 is kept bit for bit:
// dividing by its float length could move a last bit, so a pose or axis the library handed out
// (normalised, within four roundings of 1) would come back as another one. Eight float ulps of 1.
constexpr double kKeptAsUnit = 8.0 * 1.1920928955078125e-07;

bool finite_quat(const Quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

double squared_length(const Quat& q) {
  return double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z + double(q.w) * q.w;
}

double squared_length(Vec3 v) { return double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z; }

}  // namespace

RigidTransform pose_from_caller(Vec3 position, Quat q, const std::string& field) {
  require_finite_vec3_field(position, field + ".position");
  if (!finite_quat(q))
    throw FieldError(Status::InvalidArgument, field + ".rotation", "has a non-finite component");
  if (q.x == 0.0f && q.y == 0.0f && q.z == 0.0f && q.w == 0.0f)
    return RigidTransform{position, Quat{0.0f, 0.0f, 0.0f, 1.0f}};  // a zeroed struct: the identity
  // The length in double: a float's square under- or overflows for components beyond about
  // 1e-19 or 1e19, which are still finite quaternions with a direction.
  const double n2 = squared_length(q);
  if (std::fabs(n2 - 1.0) <= kKeptAsUnit) return RigidTransform{position, q};
  const double n = std::sqrt(n2);
  if (!(n > 1e-6))
    throw FieldError(Status::InvalidArgument, field + ".rotation",
                     "is not a rotation (length " + describe_value(static_cast<float>(n)) +
                         "; give a unit quaternion, or all zeros for the identity)");
  return RigidTransform{position, Quat{static_cast<float>(q.x / n), static_cast<float>(q.y / n),
                                       static_cast<float>(q.z / n), static_cast<float>(q.w / n)}};
}

Vec3 unit_axis_from_caller(Vec3 axis, const std::string& field, const std::string& what) {
  require_finite_vec3_field(axis, field);
  const double n2 = squared_length(axis);
  if (std::fabs(n2 - 1.0) <= kKeptAsUnit) return axis;
  const double n = std::sqrt(n2);
  if (!(n > 0.0)) throw FieldError(Status::InvalidArgument, field, what + " needs a non-zero axis");
  return Vec3{static_cast<float>(axis.x / n), static_cast<float>(axis.y / n), static_cast<float>(axis.z / n)};
}

void require_pose(const RigidTransform& pose, const std::string& field) {
  require_finite_vec3_field(pose.position, field + ".position");
  if (!finite_quat(pose.rotation))
    throw FieldError(Status::InvalidArgument, field + ".rotation", "has a non-finite component");
  if (!(std::fabs(squared_length(pose.rotation) - 1.0) < kUnitTolerance))
    throw FieldError(Status::InvalidArgument, field + ".rotation", "is not a unit quaternion");
}

void require_unit_axis(Vec3 axis, const std::string& field, const std::string& what) {
  require_finite_vec3_field(axis, field);
  if (!(std::fabs(squared_length(axis) - 1.0) < kUnitTolerance))
    throw FieldError(Status::InvalidArgument, field, what + " needs a unit axis");
}

}  // namespace sph
