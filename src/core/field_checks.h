// SPDX-License-Identifier: MIT
// Range checks of spec fields for the world's entry points; each throws a FieldError that
// names the field (field_error.h).
#pragma once

#include <cmath>
#include <string>

#include "../physics/vec3.h"
#include "field_error.h"
#include "param_validation.h"  // describe_value: the shortest decimal that reads back as the float

namespace sph {

inline void require_finite_field(float v, const std::string& field) {
  if (!std::isfinite(v)) throw FieldError(Status::InvalidArgument, field, "is not finite");
}

inline void require_non_negative_field(float v, const std::string& field) {
  require_finite_field(v, field);
  if (v < 0.0f) throw FieldError(Status::InvalidArgument, field, "must be >= 0, got " + describe_value(v));
}

inline void require_finite_vec3_field(const Vec3& v, const std::string& field) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw FieldError(Status::InvalidArgument, field, "has a non-finite component");
}

// A particle velocity: finite, and its squared length finite in float32 (a speed below
// 1.8e19 m/s). A step takes |v|^2 for the step size and its non-finite check, so a particle
// faster than that could never step (issue 23: spawned at 2e19 m/s, the world's carried max
// speed became +Inf).
inline bool speed_fits_float(const Vec3& v) { return std::isfinite(length_squared(v)); }

inline void require_particle_velocity_field(const Vec3& v, const std::string& field) {
  require_finite_vec3_field(v, field);
  if (!speed_fits_float(v))
    throw FieldError(Status::InvalidArgument, field,
                     "its speed's square overflows float32 (speeds must be below 1.8e19 m/s; a step would "
                     "treat the particle as non-finite)");
}

}  // namespace sph
