// SPDX-License-Identifier: MIT
// The regions of an axis-aligned box of half extent kHalf that physics_loads_breakdown
// (loads_breakdown.cpp) sums the walls' reaction over: a point beyond one of the box's axes lies
// by a face, beyond two by an edge, beyond three by a corner, beyond none inside the box's extent.
#pragma once

#include <cmath>

namespace loads_breakdown {

const double kHalf = 0.03;  // m, the submerged box's half extent (test_collider_loads.c)

enum Region {
  kTop,
  kBottom,
  kSides,
  kEdgeTop,
  kEdgeBottom,
  kEdgeVertical,
  kCornerTop,
  kCornerBottom,
  kInside,
  kRegions
};
const char* const kRegionNames[kRegions] = {"top face",    "bottom face",    "side faces",
                                            "top edges",   "bottom edges",   "vertical edges",
                                            "top corners", "bottom corners", "inside the box"};

inline Region region_of(const double local[3]) {
  const bool out[3] = {std::fabs(local[0]) > kHalf, std::fabs(local[1]) > kHalf, std::fabs(local[2]) > kHalf};
  const int count = out[0] + out[1] + out[2];
  const bool up = local[1] > 0.0;
  if (count == 0) return kInside;
  if (count == 3) return up ? kCornerTop : kCornerBottom;
  if (count == 2) return out[1] ? (up ? kEdgeTop : kEdgeBottom) : kEdgeVertical;
  return out[1] ? (up ? kTop : kBottom) : kSides;
}

}  // namespace loads_breakdown
