// SPDX-License-Identifier: MIT
// The small DFSPH dam break of the GPU checks (check_dfsph_cg.cpp, check_dfsph_masks.cpp): the
// geometry of dam_break_run (tests/support/dam_break.c), a column `layers` lattice layers across
// and twice as high, a slab 6 layers deep, the tank's walls (at the lattice's faces) as a
// collider so that the contacts are exercised, gravity, viscosity 0.05, step factor 0.4, dt_max
// one frame.
#pragma once

#include <cmath>
#include <cstdlib>
#include <vector>

#include "gpu_check.h"

namespace gpu_check {

struct DfsphDamBreak {
  sph_world* world = nullptr;
  sph_sdf* tank = nullptr;
  std::vector<float> start;  // the particles' start positions (xyz), as spawned
  float kernel_radius = 0.0f;

  DfsphDamBreak() = default;
  DfsphDamBreak(const DfsphDamBreak&) = delete;
  DfsphDamBreak& operator=(const DfsphDamBreak&) = delete;
  ~DfsphDamBreak() {
    sph_world_destroy(world);
    sph_sdf_destroy(tank);
  }
};

// kernel_ratio: the kernel radius in particle spacings (0: the library's default). The solve's
// parameters are the caller's (set before the particles are spawned).
inline void make_dfsph_dam_break(sph_context* context, uint32_t layers_across, float frame, double gravity,
                                 float kernel_ratio, const sph_dfsph_params& dfsph, DfsphDamBreak* out) {
  const double a = 0.05715, step = a / layers_across;
  const uint32_t layers[3] = {layers_across, 2 * layers_across, 6};
  const double tank_min[3] = {0.0, 0.0, 0.0};
  const double tank_max[3] = {6.0 * a, 3.0 * a, step * layers[2]};
  float* positions = nullptr;
  uint32_t n = 0;
  require_ok(support_fcc_box(layers, step, nullptr, &positions, &n), "support_fcc_box");
  out->start.assign(positions, positions + 3 * static_cast<size_t>(n));
  std::free(positions);
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = n;
  def.particle_spacing = static_cast<float>(step * std::sqrt(2.0));
  if (kernel_ratio > 0.0f) def.kernel_radius = kernel_ratio * def.particle_spacing;
  def.solver = SPH_SOLVER_DFSPH;
  def.equation_of_state = SPH_EOS_IDEAL_GAS;
  require_ok(sph_world_create(context, &def, &out->world), "sph_world_create");
  sph_world_def resolved;
  sph_world_def_init(&resolved);
  require_ok(sph_world_get_def(out->world, &resolved), "sph_world_get_def");
  out->kernel_radius = resolved.kernel_radius;
  sph_world_params params;
  sph_world_params_init(&params);
  params.gravity.y = static_cast<float>(-gravity);
  params.viscosity = 0.05f;
  params.step_factor = 0.4f;
  params.dt_max = frame;
  params.max_substeps = 100000;
  require_ok(sph_world_set_params(out->world, &params), "sph_world_set_params");
  require_ok(sph_world_set_dfsph_params(out->world, &dfsph), "sph_world_set_dfsph_params");
  require_ok(
      support_tank_between(context, out->world, tank_min, tank_max, 0.5 * step, 0.0f, &out->tank, nullptr),
      "support_tank_between");
  require_ok(support_spawn(out->world, out->start.data(), nullptr, n), "support_spawn");
}

}  // namespace gpu_check
