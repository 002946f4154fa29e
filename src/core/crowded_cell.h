// SPDX-License-Identifier: MIT
// The bound on one grid slot's crowd, shared by both backends (docs/reliability.md, "What one
// call may cost"): a step whose neighbour grid finds more particles in one slot than this is
// refused with SPH_ERROR_CAPACITY and rolled back, so that no pile of coincident particles can
// make a step's neighbour work grow with the square of the particle count.
#pragma once

#include <stdint.h>

#include <string>

#include "../physics/vec3.h"

namespace sph {

// A cell may hold this many times the particles a cell of fluid at rest holds (sqrt(2) h^3 /
// spacing^3, the FCC lattice's number density) before a step is refused: 64 times the rest
// density is far beyond any state of the weakly compressible fluids (a few per cent) or the
// gases the solver models, and it bounds the candidates one particle visits to 27 times the
// cap (64 times a fluid at rest's), whatever the particles do.
constexpr double kMaxCellDensityRatio = 64.0;
constexpr uint32_t kMinCellCap = 64;

// The most particles one grid slot may hold for a world of this spacing and kernel radius.
uint32_t max_particles_per_cell(float particle_spacing, float kernel_radius);

// The refusal's message: `held` particles in one slot, one of them at `where`, `cap` allowed.
std::string crowded_cell_message(uint32_t held, Vec3 where, uint32_t cap);

}  // namespace sph
