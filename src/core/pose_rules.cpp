// SPDX-License-Identifier: MIT
#include "pose_rules.h"

#include <cmath>

#include "field_checks.h"

namespace sph {
namespace {

// How far from 1 a stored unit quaternion's squared length may be: far above float rounding
// (a few 1e-7), far below any rotation a caller meant to be different.
constexpr double kUnitTolerance = 1e-3;

bool finite_quat(const Quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

double squared_length(const Quat& q) {
  return double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z + double(q.w) * q.w;
}

}  // namespace

RigidTransform pose_from_caller(Vec3 position, Quat q, const std::string& field) {
  require_finite_vec3_field(position, field + ".position");
  if (!finite_quat(q))
    throw FieldError(Status::InvalidArgument, field + ".rotation", "has a non-finite component");
  if (q.x == 0.0f && q.y == 0.0f && q.z == 0.0f && q.w == 0.0f)
    return RigidTransform{position, Quat{0.0f, 0.0f, 0.0f, 1.0f}};  // a zeroed struct: the identity
  const float n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(n > 1e-6f) || !std::isfinite(n))
    throw FieldError(Status::InvalidArgument, field + ".rotation",
                     "is not a rotation (length " + describe_value(n) +
                         "; give a unit quaternion, or all zeros for the identity)");
  return RigidTransform{position, Quat{q.x / n, q.y / n, q.z / n, q.w / n}};
}

Vec3 unit_axis_from_caller(Vec3 axis, const std::string& field, const std::string& what) {
  require_finite_vec3_field(axis, field);
  const float n = length(axis);
  if (!(n > 0.0f) || !std::isfinite(n))
    throw FieldError(Status::InvalidArgument, field, what + " needs a non-zero axis");
  return axis * (1.0f / n);
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
  const double n2 = double(axis.x) * axis.x + double(axis.y) * axis.y + double(axis.z) * axis.z;
  if (!(std::fabs(n2 - 1.0) < kUnitTolerance))
    throw FieldError(Status::InvalidArgument, field, what + " needs a unit axis");
}

}  // namespace sph
