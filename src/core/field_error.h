// SPDX-License-Identifier: MIT
// Errors about one field of a spec handed to a world's entry point. The core names the field
// relative to the spec ("restitution", "pose.rotation", "positions[3]"); a caller that knows
// where the spec came from puts that path in front: the C layer "def->", the checkpoint
// reader "collider slot 2 ". Errors that concern no field (a full world) stay plain Errors and
// pass through unchanged.
#pragma once

#include <string>
#include <utility>

#include "status.h"

namespace sph {

class FieldError : public Error {
 public:
  FieldError(Status status, const std::string& field, const std::string& detail)
      : Error(status, field + ": " + detail), field_(field), detail_(detail) {}
  const std::string& field() const { return field_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string field_;
  std::string detail_;
};

// Runs body(); a FieldError it throws comes out with `prefix` in front of its field.
template <class Body>
auto with_field_prefix(const std::string& prefix, Body&& body) -> decltype(body()) {
  try {
    return std::forward<Body>(body)();
  } catch (const FieldError& e) {
    throw FieldError(e.status(), prefix + e.field(), e.detail());
  }
}

}  // namespace sph
