// SPDX-License-Identifier: MIT
// Rotations from callers and the rule every pose inside a world obeys. The public structs take
// any non-zero quaternion (the library normalises it) and read the all-zero quaternion of a
// zeroed struct as the identity; inside, a pose has a finite position and a unit rotation.
// Normalising is the C layer's conversion (pose_from_caller), not the entry points' job,
// because dividing an already normalised quaternion by its float length can move its last
// bit: a checkpoint's poses must come back exactly as they were saved.
#pragma once

#include <string>

#include "../physics/rigid_transform.h"

namespace sph {

// A caller's position and quaternion as a pose: the position must be finite; the all-zero
// quaternion is the identity; any other must be finite and longer than 1e-6, and is divided by
// its length (in double), unless it is a unit quaternion to float precision (squared length
// within 8 ulps of 1), which is kept bit for bit: a pose read back from the library and given
// again is the same pose. Throws FieldError naming field + ".position" or field + ".rotation".
RigidTransform pose_from_caller(Vec3 position, Quat rotation, const std::string& field);

// A caller's axis as a unit vector: finite and longer than 0, divided by its length (in double),
// or kept bit for bit when it is a unit vector to float precision (as pose_from_caller).
// Throws FieldError naming `field`; `what` says what needs the axis ("a vortex").
Vec3 unit_axis_from_caller(Vec3 axis, const std::string& field, const std::string& what);

// The entry points' rule: a finite position and a rotation whose squared length is within
// 1e-3 of 1 (any quaternion pose_from_caller made). Throws FieldError naming field + ".*".
void require_pose(const RigidTransform& pose, const std::string& field);

// A unit vector within the same tolerance. Throws FieldError naming `field`.
void require_unit_axis(Vec3 axis, const std::string& field, const std::string& what);

}  // namespace sph
