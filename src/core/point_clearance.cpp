// SPDX-License-Identifier: MIT
#include "point_clearance.h"

#include <stdint.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace sph {
namespace {

// Cells of edge min_distance keyed by packed 21-bit coordinates; points beyond the packable
// range share border cells, which only adds candidates to test, never misses one.
uint64_t cell_key(Vec3 p, float inv) {
  auto axis = [&](float x) {
    const double c = std::floor(static_cast<double>(x) * inv) + 1048576.0;
    return static_cast<uint64_t>(std::clamp(c, 0.0, 2097151.0));
  };
  return axis(p.x) | (axis(p.y) << 21) | (axis(p.z) << 42);
}

}  // namespace

HostVector<char> clear_of_points(const HostVector<Vec3>& existing, const HostVector<Vec3>& candidates,
                                 float min_distance) {
  HostVector<char> keep(candidates.size(), 1);
  if (existing.empty() || !(min_distance > 0.0f)) return keep;
  const float inv = 1.0f / min_distance;
  HostVector<std::pair<uint64_t, uint32_t>> cells(existing.size());
  for (size_t i = 0; i < existing.size(); ++i)
    cells[i] = {cell_key(existing[i], inv), static_cast<uint32_t>(i)};
  std::sort(cells.begin(), cells.end());
  const float r2 = min_distance * min_distance;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const Vec3 p = candidates[c];
    bool clear = true;
    for (int dz = -1; dz <= 1 && clear; ++dz)
      for (int dy = -1; dy <= 1 && clear; ++dy)
        for (int dx = -1; dx <= 1 && clear; ++dx) {
          const Vec3 q{p.x + static_cast<float>(dx) * min_distance,
                       p.y + static_cast<float>(dy) * min_distance,
                       p.z + static_cast<float>(dz) * min_distance};
          const uint64_t key = cell_key(q, inv);
          auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(key, uint32_t{0}));
          for (; it != cells.end() && it->first == key; ++it)
            if (length_squared(existing[it->second] - p) < r2) {
              clear = false;
              break;
            }
        }
    keep[c] = clear ? 1 : 0;
  }
  return keep;
}

}  // namespace sph
