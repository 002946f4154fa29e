// SPDX-License-Identifier: MIT
// The CPU backend's neighbour passes on SIMD lanes, chosen at run time for the processor: the
// same shared pair terms (src/physics) instantiated for 16 lanes of AVX-512, AVX2, or plain
// floats (every build has the generic target; x86-64 builds add the other two, each from its
// own file compiled with its -m flags). Each call gathers one particle, like the scalar gathers
// of src/physics (gather_density, gather_acceleration, ...), and returns what they return within
// float rounding: the terms are the same, only the order of the sums differs (16 lane sums
// combined in a fixed tree). Every target computes the same bits (cpu_simd_lanes.h).
#pragma once

#include <stdint.h>

#include "../physics/density.h"
#include "../physics/dfsph_passes.h"
#include "../physics/fluid_constants.h"
#include "../physics/methods.h"
#include "../physics/neighbor_walk.h"
#include "cpu_neighbor_columns.h"

namespace sph {

enum class SimdTarget : uint32_t { Generic = 0, Avx2 = 1, Avx512 = 2 };

struct SimdPasses {
  using DensityFn = DensitySample (*)(const FluidBase&, const GridView&, const NeighborColumns&, uint32_t);
  // Eq. 31 over the carried densities (gather_normalized_density).
  using NormalizedDensityFn = float (*)(const FluidBase&, const GridView&, const NeighborColumns&, uint32_t);
  // The density diffusion's rate D_i over the published densities (gather_density_diffusion).
  using DensityDiffusionFn = float (*)(const FluidConstants&, const GridView&, const NeighborColumns&,
                                       uint32_t);
  // The colour-field record (n_i, |n_i|) (gather_colour_normal).
  using ColourNormalFn = Float4 (*)(const FluidBase&, const GridView&, const NeighborColumns&, uint32_t);
  // The acceleration of the neighbour terms and gravity (gather_acceleration), for one
  // combination of force terms.
  using AccelerationFn = Vec3 (*)(const FluidConstants&, const GridView&, const NeighborColumns&, uint32_t);

  using DfsphFactorFn = DfsphDensitySample (*)(const FluidBase&, const GridView&, const NeighborColumns&,
                                               const BoundaryShare&, uint32_t);
  using DfsphRateFn = float (*)(const FluidBase&, const GridView&, const NeighborColumns&, const DfsphWalls&,
                                uint32_t);
  using DfsphVelocityChangeFn = Vec3 (*)(const FluidBase&, const GridView&, const NeighborColumns&,
                                         const float*, const DfsphWalls&, uint32_t, float);

  SimdTarget target;
  const char* name;  // "generic", "avx2", "avx512"
  DensityFn density;
  NormalizedDensityFn normalized_density;
  DensityDiffusionFn density_diffusion;
  ColourNormalFn colour_normal;
  // The acceleration function for the force terms a world runs (methods.h, with_force_terms).
  AccelerationFn (*acceleration_for)(const MethodSelection&);
  // The same without the pressure force (gather_acceleration<Terms, false>): DFSPH's
  // non-pressure accelerations.
  AccelerationFn (*acceleration_without_pressure_for)(const MethodSelection&);
  // DFSPH's three gathers (dfsph_passes.h): the density and factor (gather_density_and_factor,
  // wall: the walls' share at x_i), D rho_i / Dt over the columns' velocities (density_rate),
  // and the velocity change from the pressures k (pressure_velocity_change; k padded as a
  // column, kLanePadding elements past the particles).
  DfsphFactorFn dfsph_density_and_factor;
  DfsphRateFn dfsph_density_rate;
  DfsphVelocityChangeFn dfsph_velocity_change;
  // The same with the corrected gradient (pressure_velocity_change<true>, SPH_DFSPH_CORRECTED_GRADIENT).
  DfsphVelocityChangeFn dfsph_velocity_change_corrected;
};

// The passes of a target, or null when this build does not have it.
const SimdPasses* simd_passes_built(SimdTarget target);

// Whether this processor (and its operating system) runs a target's instructions.
bool simd_target_runs(SimdTarget target);

// The best target this build has and this processor runs.
const SimdPasses& best_simd_passes();

// The targets' tables, one per file (the x86 ones only in x86-64 builds). Constants, so that
// nothing of a target's file runs before the processor is known to run its instructions.
extern const SimdPasses kSimdPassesGeneric;
extern const SimdPasses kSimdPassesAvx2;
extern const SimdPasses kSimdPassesAvx512;

}  // namespace sph
