// SPDX-License-Identifier: MIT
#include "crowded_cell.h"

#include <algorithm>
#include <cmath>

namespace sph {

uint32_t max_particles_per_cell(float particle_spacing, float kernel_radius) {
  const double per_axis = static_cast<double>(kernel_radius) / static_cast<double>(particle_spacing);
  const double rest = std::sqrt(2.0) * per_axis * per_axis * per_axis;
  const double cap = std::ceil(kMaxCellDensityRatio * rest);
  return static_cast<uint32_t>(std::min(std::max(cap, static_cast<double>(kMinCellCap)), 1e9));
}

std::string crowded_cell_message(uint32_t held, Vec3 where, uint32_t cap) {
  return "neighbour grid: " + std::to_string(held) + " particles share one cell (near (" +
         std::to_string(where.x) + ", " + std::to_string(where.y) + ", " + std::to_string(where.z) +
         ")); at most " + std::to_string(cap) +
         " may (64 times the rest density), so the step was refused and rolled back: "
         "remove or spread the piled-up particles";
}

}  // namespace sph
