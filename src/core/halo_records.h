// SPDX-License-Identifier: MIT
// What a distributed world's ghosts take from their owners after a density pass (the CPU rank,
// src/cpu/cpu_halo.cpp, and the CUDA rank, cuda/cuda_halo.cu, send the same record): the
// density, pressure, 1 / density and neighbour count the force pass reads of a neighbour,
// behind the particle's id, which the receiver checks against its ghost.
#pragma once

#include <stdint.h>

namespace sph {

struct HaloDensityRecord {
  uint32_t id;
  float density, pressure, inv_density;
  uint32_t neighbors;
};

static_assert(sizeof(HaloDensityRecord) == 20, "a density record is five words");

}  // namespace sph
