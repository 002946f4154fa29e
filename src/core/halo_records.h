// SPDX-License-Identifier: MIT
// What a distributed world's ghosts take from their owners after a density pass (the CPU rank,
// src/cpu/cpu_halo.cpp, and the CUDA rank, cuda/cuda_halo.cu, send the same records): the
// density, pressure, 1 / density and neighbour count the force pass reads of a neighbour, and
// with surface tension the colour normal, behind the particle's id, which the receiver checks
// against its ghost. DFSPH's (src/cpu/cpu_halo_solvers.cpp, cuda/cuda_halo_dfsph.cu): after its
// density pass the factor in the pressure's place, then in each solve iteration the velocities
// and the pressure steps k (core/dfsph_jacobi_loop.h says when).
#pragma once

#include <stdint.h>

#include "../physics/float4_types.h"

namespace sph {

struct HaloDensityRecord {
  uint32_t id;
  float density, pressure, inv_density;
  uint32_t neighbors;
};

static_assert(sizeof(HaloDensityRecord) == 20, "a density record is five words");

// With surface tension, after the colour normals' pass: each ghost takes its owner's normal
// (the force pass reads it). The padding is a member, zeroed: Float4's alignment would otherwise
// put 12 bytes of indeterminate memory on the wire.
struct HaloNormalRecord {
  uint32_t id;
  uint32_t padding[3];
  Float4 normal;
};

static_assert(sizeof(HaloNormalRecord) == 32, "a colour normal's record has no implicit padding");

// DFSPH's density pass: what its solves and force pass read of a neighbour.
struct HaloDfsphDensityRecord {
  uint32_t id;
  float density, factor, inv_density;
  uint32_t neighbors;
};

static_assert(sizeof(HaloDfsphDensityRecord) == 20, "a DFSPH density record is five words");

// A DFSPH solve's velocity update: the solve's velocity (w: 1 / rho). Padded as the normal's.
struct HaloVelocityRecord {
  uint32_t id;
  uint32_t padding[3];
  Float4 velocity;
};

static_assert(sizeof(HaloVelocityRecord) == 32, "a velocity's record has no implicit padding");

// A DFSPH solve's rate pass: the pressure step k.
struct HaloDfsphStepRecord {
  uint32_t id;
  float k;
};

static_assert(sizeof(HaloDfsphStepRecord) == 8, "a pressure step's record is two words");

// Springs' linking, between its two passes (src/cpu/cpu_halo_springs.cpp, cuda/cuda_halo_springs.cu):
// an owned particle's nearest candidates (pass 1), as ids, nearest first, padded with kNoSpring
// (physics/springs.h's kSpringSlots of them: 16).
struct HaloSpringCandidateRecord {
  uint32_t id;
  uint32_t candidate[16];
};

static_assert(sizeof(HaloSpringCandidateRecord) == 68, "a spring candidates' record is 17 words");

}  // namespace sph
