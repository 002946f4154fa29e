// SPDX-License-Identifier: MIT
// The per-particle passes of a substep on the device: reorder into the sorted working copy,
// density and pressure, then forces with integration. Each kernel is one thread per particle
// calling the shared physics of src/physics; the host functions here only launch them.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/physics/collider_response.h"
#include "../src/physics/fluid_constants.h"
#include "../src/physics/force_fields.h"
#include "../src/physics/forces.h"
#include "../src/physics/neighbor_walk.h"
#include "device_neighbor_grid.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

struct KernelTuning {
  unsigned density_block = 128;
  unsigned force_block = 128;
  // Threads per particle of the density pass and the weakly compressible force passes (a lane
  // group, force_gather.cuh): 1, 2, 4 or 8, or 0 to choose by the particle count
  // (lanes_per_particle). The lanes split each run of candidates and add their sums in a fixed
  // order, so a result depends on this count (the last bits of the sums), never on timing.
  unsigned particle_lanes = 0;
  // Threads the device keeps resident at once (SMs x threads per SM), for the choice by count;
  // 0 = unknown (one lane).
  unsigned thread_slots = 0;
};

// The lane group of the neighbour passes for n particles: tuning.particle_lanes if set, else
// the fewest lanes (1, 2 or 4) with which n particles fill the device's thread slots.
unsigned lanes_per_particle(const KernelTuning& tuning, uint32_t n);

// The scene inside a substep, as the kernels see it: the views live in a per-world device
// buffer uploaded before each frame (their SdfGridViews point at the world's device copies of
// the assets). All zero for a frame without colliders or force fields.
struct DeviceScene {
  const ColliderView* colliders = nullptr;
  const ForceFieldView* fields = nullptr;
  uint32_t collider_count = 0;
  uint32_t field_count = 0;
  float kernel_radius = 0.0f;  // for stickiness

  bool active() const { return collider_count != 0 || field_count != 0; }
};

// What the RK4 reorder carries along: nothing (Euler), the start state built from the current
// state (stage 0), or the start state and slope sums of the previous stage.
enum class Rk4Carry { None, BuildStart, Gather };

// sorted_position[i] = position[order[i]] (w = order[i] as bits, read back by the density
// pass), sorted_id likewise; RK4 state from side `from` to side 1 - from. When the cell-start
// pass found a crowded slot, the table is emptied instead of walked (guard) and the slot's first
// particle's position recorded for the message.
void enqueue_reorder(const ParticleArrays& a, const uint32_t* order, uint32_t n, Rk4Carry carry, int from,
                     const CrowdGuard& guard, FrameState* state, cudaStream_t stream);

// The physics options a world was created with (methods: src/physics/methods.h).
struct SubstepOptions {
  MethodSelection methods{};  // every method the world runs; the force pass dispatches on it
  bool surface_tension = false;
  bool normalized_density = false;
  bool density_diffusion = false;  // with normalized_density: delta-SPH on the carried density
  ViscosityMethod viscosity = ViscosityMethod::Mueller;
  bool springs = false;  // a.spring_acceleration adds to the force pass
  bool dfsph = false;    // the DFSPH solver (dfsph_solver.h) instead of the weakly compressible passes
  bool boundary_density = false;  // the colliders' share joins the density; the walls' pressure the forces
};

// density[i], sorted_position[i].w = pressure, sorted_velocity[i] = (velocity[order[i]], 1/rho);
// with the options, the neighbour counts, the normalised density (eq. 31, published into the
// same three places) and the colour-field normals, in the CPU backend's order. With
// options.boundary_density the scene's colliders add their share (posed at the substep's time
// at `stage_fraction` of it, boundary_density.h's stage_time) and a.boundary_gradient is written.
// With options.density_diffusion and first_of_substep the density diffusion follows the
// normalised density (enqueue_density_diffusion), before the colour-field normals.
void enqueue_density(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a, uint32_t n,
                     const SubstepOptions& options, const KernelTuning& tuning, const DeviceScene& scene,
                     float stage_fraction, bool first_of_substep, FrameState* state, cudaStream_t stream);

// enqueue_density in its parts, for a distributed rank whose ghosts take their owners' records
// after each publication of the densities (SubstepHooks::after_density): the summation (the
// density kernel), then what publishes them again (the normalised density's filter, or the
// diffusion where first_of_substep; without it the factors are carried): returns whether it
// did. (The colour-field normals follow, enqueue_colour_normals.)
void enqueue_density_summation(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                               const DeviceScene& scene, float stage_fraction, FrameState* state,
                               cudaStream_t stream);
bool enqueue_density_republish(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                               bool first_of_substep, FrameState* state, cudaStream_t stream);

// SPH_FEATURE_DENSITY_DIFFUSION (density_diffusion.h): the delta-SPH term over the published
// densities, applied for the substep's dt (read from the state) through the carried factors and
// republished into the same three places. Once per substep, after its first density pass.
void enqueue_density_diffusion(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                               uint32_t n, const KernelTuning& tuning, FrameState* state,
                               cudaStream_t stream);

// colour_normal[i] for surface tension, after the density pass (enqueue_density calls it).
void enqueue_colour_normals(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                            uint32_t n, const KernelTuning& tuning, cudaStream_t stream);

// Symplectic Euler from the sorted copy into the state, with the max-speed and
// max-acceleration reductions and the non-finite check.
// With a scene: the force fields add to the gathered acceleration, and the colliders resolve
// the integrated state from the particle's position before the step (FrameState::time), unless
// collide_here is false: then the loads pass (device_collider_loads.h) resolves them and takes
// the state's max speed.
void enqueue_forces_euler(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                          uint32_t n, const SubstepOptions& options, const KernelTuning& tuning,
                          const DeviceScene& scene, bool collide_here, FrameState* state,
                          cudaStream_t stream);

// One RK4 stage (0..3); its start state and slope sums are on side (stage + 1) % 2. The
// colliders act after the last stage, from the start position (collide_here as for Euler).
void enqueue_forces_rk4(const FluidConstants& fluid, const GridView& grid, const ParticleArrays& a,
                        uint32_t n, int stage, const SubstepOptions& options, const KernelTuning& tuning,
                        const DeviceScene& scene, bool collide_here, FrameState* state, cudaStream_t stream);

}  // namespace sph
