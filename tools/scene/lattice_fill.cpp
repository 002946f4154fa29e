// SPDX-License-Identifier: MIT
#include "lattice_fill.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace sph_tools {

namespace {

struct ScratchWorld {
  sph_world* world = nullptr;
  ~ScratchWorld() { sph_world_destroy(world); }
};

sph_result fill(sph_world* world, const FluidDesc& f) {
  if (f.kind == FluidDesc::Kind::kBox) {
    sph_fill_box_desc d;
    sph_fill_box_desc_init(&d);
    d.min = f.min;
    d.max = f.max;
    d.velocity = f.velocity;
    return sph_world_fill_box(world, &d, nullptr);
  }
  sph_fill_sphere_desc d;
  sph_fill_sphere_desc_init(&d);
  d.center = f.center;
  d.radius = f.radius;
  d.velocity = f.velocity;
  return sph_world_fill_sphere(world, &d, nullptr);
}

}  // namespace

sph_result lattice_fill(sph_context* context, const sph_world_def& def, const FluidDesc& f,
                        std::vector<float>* positions, std::vector<float>* velocities) {
  if (f.kind == FluidDesc::Kind::kParticles) {
    *positions = f.positions;
    *velocities = f.velocities;
    if (velocities->empty())
      for (size_t i = 0; i < f.positions.size(); i += 3)
        velocities->insert(velocities->end(), {f.velocity.x, f.velocity.y, f.velocity.z});
    return SPH_OK;
  }
  // A plain world of the same def: features a distributed world refuses do not matter to a fill.
  ScratchWorld scratch;
  sph_result r = sph_world_create(context, &def, &scratch.world);
  if (r < 0) return r;
  r = fill(scratch.world, f);
  if (r < 0) return r;
  uint32_t n = 0;
  r = sph_world_get_particle_count(scratch.world, &n);
  if (r < 0) return r;
  std::vector<float> x(3 * static_cast<size_t>(n)), v(3 * static_cast<size_t>(n));
  std::vector<uint32_t> id(n);
  uint32_t written = 0;
  if (n > 0) {
    if ((r = sph_world_copy_attribute(scratch.world, SPH_ATTRIBUTE_POSITION, x.data(), 12ull * n, 0, 0, n,
                                      &written)) < 0 ||
        (r = sph_world_copy_attribute(scratch.world, SPH_ATTRIBUTE_VELOCITY, v.data(), 12ull * n, 0, 0, n,
                                      &written)) < 0 ||
        (r = sph_world_copy_attribute(scratch.world, SPH_ATTRIBUTE_ID, id.data(), 4ull * n, 0, 0, n,
                                      &written)) < 0)
      return r;
  }
  // Ids follow the fill's order; the world's own order is not promised to.
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return id[a] < id[b]; });
  positions->resize(3 * static_cast<size_t>(n));
  velocities->resize(3 * static_cast<size_t>(n));
  for (uint32_t k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) {
      (*positions)[3 * static_cast<size_t>(k) + c] = x[3 * static_cast<size_t>(order[k]) + c];
      (*velocities)[3 * static_cast<size_t>(k) + c] = v[3 * static_cast<size_t>(order[k]) + c];
    }
  return SPH_OK;
}

}  // namespace sph_tools
