// SPDX-License-Identifier: MIT
// A box of an SDF grid's voxels: what a change of an asset touched (sph_sdf_update's box) and what
// the CPU's boundary maps recompute after it (src/cpu/cpu_boundary_maps.h).
#pragma once

#include <stdint.h>

#include <algorithm>

namespace sph {

// [lo, hi) along each index axis; empty when any hi <= lo.
struct VoxelBox {
  int32_t lo[3] = {0, 0, 0};
  int32_t hi[3] = {0, 0, 0};
  bool empty() const { return !(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2]); }
  uint64_t voxels() const {
    return empty() ? 0 : static_cast<uint64_t>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  }
  // The smallest box holding both (an empty box adds nothing).
  VoxelBox joined(const VoxelBox& o) const {
    if (o.empty()) return *this;
    if (empty()) return o;
    VoxelBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = std::min(lo[a], o.lo[a]), b.hi[a] = std::max(hi[a], o.hi[a]);
    return b;
  }
  VoxelBox intersected(const VoxelBox& o) const {
    VoxelBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = std::max(lo[a], o.lo[a]), b.hi[a] = std::min(hi[a], o.hi[a]);
    return b.empty() ? VoxelBox{} : b;
  }
};

}  // namespace sph
