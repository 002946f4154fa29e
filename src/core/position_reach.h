// SPDX-License-Identifier: MIT
// How far from the origin a particle may be. Float32 resolves a position x to steps of about
// |x| 2^-23. Beyond 2^16 particle spacings from the origin a step exceeds 1/128 of the spacing,
// and neighbour distances, densities and small moves turn to rounding noise (at 1e6 m with a
// 2 cm spacing the steps are 6 cm: silent garbage), so such positions are refused, whatever
// brings a particle there: a spawn, a fill, a write, a source's emission. The bound lies far
// inside the neighbour grid's cell-coordinate range (2^30 cells of h >= spacing).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "../physics/rigid_transform.h"
#include "field_checks.h"
#include "host_memory.h"

namespace sph {

constexpr float kMaxPositionInSpacings = 65536.0f;

// "" when p is within reach, else why not (for an error message after the field's name).
inline std::string resolution_problem(const Vec3& p, float spacing) {
  const float limit = kMaxPositionInSpacings * spacing;
  if (std::fabs(p.x) <= limit && std::fabs(p.y) <= limit && std::fabs(p.z) <= limit) return {};
  return "(" + describe_value(p.x) + ", " + describe_value(p.y) + ", " + describe_value(p.z) +
         ") lies farther than " + describe_value(limit) +
         " m (65536 particle spacings) from the origin, where float32 positions no longer "
         "resolve the spacing to 1/128; move the scene's origin closer or use a larger spacing";
}

// The box of a source's lattice (region-local), kept with the source so that moving it costs
// eight corner checks, not a walk over up to kMaxSourceLatticePoints points.
struct LatticeBox {
  bool empty = true;
  Vec3 lo{0.0f, 0.0f, 0.0f};
  Vec3 hi{0.0f, 0.0f, 0.0f};
};

inline LatticeBox lattice_box(const HostVector<Vec3>& lattice) {
  LatticeBox box;
  if (lattice.empty()) return box;
  box.empty = false;
  box.lo = box.hi = lattice[0];
  for (const Vec3& p : lattice) {
    box.lo = Vec3{std::min(box.lo.x, p.x), std::min(box.lo.y, p.y), std::min(box.lo.z, p.z)};
    box.hi = Vec3{std::max(box.hi.x, p.x), std::max(box.hi.y, p.y), std::max(box.hi.z, p.z)};
  }
  return box;
}

// "" when every point of a source's lattice (region-local, bounded by `box`) lies within reach at
// `pose`, else why not. The posed corners of the lattice's box bound it (|x| is convex, so its
// largest value over the posed points is at most its largest over the posed corners): a lattice
// refused lies within its box's diagonal of the bound, one accepted within it wholly.
inline std::string lattice_reach_problem(const LatticeBox& box, const RigidTransform& pose, float spacing) {
  if (box.empty) return {};
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{(c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                      (c & 4) ? box.hi.z : box.lo.z};
    const std::string problem = resolution_problem(to_world(pose, corner), spacing);
    if (!problem.empty()) return "puts the region's lattice at " + problem;
  }
  return {};
}

}  // namespace sph
