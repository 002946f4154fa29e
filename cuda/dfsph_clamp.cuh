// SPDX-License-Identifier: MIT
// DFSPH's contact clamp on the device, which the density pass (the divergence solve's warm start,
// dfsph_density.cu) and the solves' passes (dfsph_solver.cu) apply after each velocity update.
#pragma once

#include "../src/physics/collider_loads.h"
#include "../src/physics/dfsph_passes.h"
#include "device_particle_store.h"

namespace sph {

// v held to particle i's contact; with the loads, the change is added to its clamp impulses (the
// CPU backend's CpuBackend::dfsph_clamp).
__device__ inline Vec3 dfsph_clamp(const ParticleArrays& a, uint32_t i, Vec3 v) {
  const Vec3 held = respect_contact(a.dfsph_contact[i], v);
  if (a.dfsph_contact_impulse) add_clamp(a.dfsph_contact_impulse[i], v, held);
  return held;
}

}  // namespace sph
