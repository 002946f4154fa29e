// SPDX-License-Identifier: MIT
#include "particle_frame.h"

#include "library_error.h"

namespace sph_tools {

namespace {

void copy(const sph_world* world, sph_attribute a, void* dst, uint64_t bytes, uint32_t n) {
  if (n == 0) return;
  uint32_t written = 0;
  const sph_result r = sph_world_copy_attribute(world, a, dst, bytes, 0, 0, n, &written);
  if (r < 0) throw LibraryError(r, "copying particles out");
  if (written != n) throw LibraryError(SPH_ERROR_INTERNAL, "copying particles out (short copy)");
}

}  // namespace

void read_particles(const sph_world* world, uint32_t frame, double time, ParticleFrame* out) {
  uint32_t n = 0;
  sph_result r = sph_world_get_particle_count(world, &n);
  if (r < 0) throw LibraryError(r, "reading the particle count");
  sph_world_def def;
  sph_world_def_init(&def);
  r = sph_world_get_def(world, &def);
  if (r < 0) throw LibraryError(r, "reading the world's def");
  out->frame = frame;
  out->time = time;
  out->particle_spacing = def.particle_spacing;
  out->count = n;
  out->position.resize(3 * static_cast<size_t>(n));
  out->velocity.resize(3 * static_cast<size_t>(n));
  out->density.resize(n);
  out->pressure.resize(n);
  out->id.resize(n);
  copy(world, SPH_ATTRIBUTE_POSITION, out->position.data(), 12ull * n, n);
  copy(world, SPH_ATTRIBUTE_VELOCITY, out->velocity.data(), 12ull * n, n);
  copy(world, SPH_ATTRIBUTE_DENSITY, out->density.data(), 4ull * n, n);
  copy(world, SPH_ATTRIBUTE_PRESSURE, out->pressure.data(), 4ull * n, n);
  copy(world, SPH_ATTRIBUTE_ID, out->id.data(), 4ull * n, n);
  out->has_user = (def.features & SPH_FEATURE_USER_ATTRIBUTE) != 0;
  out->user.resize(out->has_user ? n : 0);
  if (out->has_user) copy(world, SPH_ATTRIBUTE_USER, out->user.data(), 4ull * n, n);
}

}  // namespace sph_tools
