// SPDX-License-Identifier: MIT
// The floating box of test_collider_loads.c (a 10 cm cube of 500 kg/m^3 dropped from 1 cm above
// water 20 cm deep in a tank 30 cm square, spacing 2 cm, h = 3.6 cm, walls in the density) on
// either solver, stepped without the loads feature, so that DFSPH (whose worlds refuse the loads
// and the probes) can be measured (issue 17 item 5; docs/validation.md, "The submerged box per
// region").
//
//   physics_loads_floating_box [--backend cpu|cuda] [--solver wcsph|dfsph]
//
// Frames of 0.5 ms, one substep each, for 3 s. The fluid's force on the box per substep is summed
// on the host as physics_loads_breakdown does (the walls' reaction m (p / rho^2) K grad Phi_box at
// the substep's start, the box's map computed here); for WCSPH the loads (contacts included) step
// the body instead and the host's sum is printed beside them. The body moves in translation only
// (no rotation: the test's box stays level to within a few milliradians), by semi-implicit Euler
// each frame. The water level is the volume of the particles over a 6 x 6 cm square of the floor
// between the box and the tank's corner (2 cm from each) divided by its area (the test's gauge
// is refused on DFSPH); the draft is that level less the box's bottom, averaged over the last
// second, against Archimedes' 5 cm.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/fcc_lattice.h"
#include "core/sdf_asset.h"
#include "core/sdf_shapes.h"
#include "cpu/cpu_boundary_maps.h"
#include "cpu/cpu_parallel.h"
#include "physics/boundary_density.h"
#include "support.h"

namespace {

const double kGravity = 9.81, kHalf = 0.05, kDepth = 0.2;

void check(sph_result r, const char* what) {
  if (r == SPH_OK) return;
  std::fprintf(stderr, "%s: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  const char* backend_name = "cpu";
  bool dfsph = false;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--backend") == 0 && k + 1 < argc)
      backend_name = argv[++k];
    else if (std::strcmp(argv[k], "--solver") == 0 && k + 1 < argc)
      dfsph = std::strcmp(argv[++k], "dfsph") == 0;
    else {
      std::fprintf(stderr, "usage: %s [--backend cpu|cuda] [--solver wcsph|dfsph]\n", argv[0]);
      return 2;
    }
  }
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = 0.02f;
  def.capacity = 8000;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | (dfsph ? 0u : SPH_FEATURE_COLLIDER_LOADS);
  if (dfsph) def.solver = SPH_SOLVER_DFSPH;
  support_world w;
  std::memset(&w, 0, sizeof w);
  check(support_world_open(&w, support_backend_from_name(backend_name, SPH_BACKEND_CPU), &def, nullptr),
        "support_world_open");
  const support_tank tank = {{0.0f, 0.25f, 0.0f}, {0.15f, 0.25f, 0.15f}, 0.01f, 0.0f};
  sph_sdf *tank_sdf = nullptr, *box_sdf = nullptr;
  check(support_tank_create(w.context, w.world, &tank, &tank_sdf, nullptr), "support_tank_create");
  sph_shape_desc shape;
  check(sph_shape_desc_init(&shape), "sph_shape_desc_init");
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = static_cast<float>(kHalf);
  shape.voxel_size = 0.01f;
  shape.padding_voxels = 8;
  check(sph_sdf_create_shape(w.context, &shape, &box_sdf), "sph_sdf_create_shape");
  const double mass = 500.0 * 8.0 * kHalf * kHalf * kHalf, archimedes = mass / (1000.0 * 4.0 * kHalf * kHalf);
  double position[3] = {0.0, kDepth + kHalf + 0.01, 0.0}, velocity[3] = {0.0, 0.0, 0.0};
  sph_collider_def collider;
  check(sph_collider_def_init(&collider), "sph_collider_def_init");
  collider.sdf = box_sdf;
  collider.transform = sph_transform_identity();
  collider.transform.position.y = static_cast<float>(position[1]);
  sph_collider_id box;
  check(sph_collider_create(w.world, &collider, &box), "sph_collider_create");
  sph_fill_box_desc water;
  sph_fill_box_desc_init(&water);
  water.min.x = -0.15f, water.min.y = 0.0f, water.min.z = -0.15f;
  water.max.x = 0.15f, water.max.y = static_cast<float>(kDepth), water.max.z = 0.15f;
  check(sph_world_fill_box(w.world, &water, nullptr), "sph_world_fill_box");

  const float h = w.def.kernel_radius, rho0 = w.def.rest_density;
  const sph::BoundaryCalibration calibration = sph::fcc_boundary_calibration(w.def.particle_spacing, h);
  const double K = calibration.scale * w.mass;
  const float level = -static_cast<float>(calibration.offset);
  sph::ShapeSpec spec;
  spec.kind = sph::ShapeKind::Box;
  spec.half_extents =
      sph::Vec3{static_cast<float>(kHalf), static_cast<float>(kHalf), static_cast<float>(kHalf)};
  spec.voxel_size = 0.01f;
  spec.padding_voxels = 8;
  const auto asset = sph::build_shape_sdf(spec, 1u << 24);
  const auto map = sph::compute_boundary_map(*asset, h, level, sph::CpuParallel(2));
  const sph::SdfGridView grid = asset->host_view();

  uint32_t n = 0;
  sph_stats stats;
  check(sph_stats_init(&stats), "sph_stats_init");
  check(sph_world_get_stats(w.world, &stats), "sph_world_get_stats");
  n = stats.particle_count;
  std::vector<float> x(3 * static_cast<size_t>(n)), after(x.size()), rho(n), p(n);
  const int frames = 6000, late = 2000;
  const double dt = 0.0005;
  double heights[6000], water_level = 0.0, mean = 0.0, host_y = 0.0, api_y = 0.0, late_time = 0.0;
  uint32_t count = 0;
  check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, x.data(), n, &count), "read positions");
  for (int frame = 0; frame < frames; ++frame) {
    check(sph_world_step(w.world, static_cast<float>(dt)), "sph_world_step");
    check(sph_world_get_stats(w.world, &stats), "sph_world_get_stats");
    if (stats.substeps != 1) {
      std::fprintf(stderr, "frame %d took %u substeps, not 1\n", frame, stats.substeps);
      return 1;
    }
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, after.data(), n, &count), "read positions");
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_DENSITY, rho.data(), n, &count), "read densities");
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_PRESSURE, p.data(), n, &count), "read pressures");
    // The walls' reaction at the substep's start, the box at its pose then (the last frame's end).
    double force[3] = {0.0, 0.0, 0.0}, column = 0.0;
    for (uint32_t i = 0; i < count; ++i) {
      const sph::Vec3 local{static_cast<float>(x[3 * i] - position[0]),
                            static_cast<float>(x[3 * i + 1] - position[1]),
                            static_cast<float>(x[3 * i + 2] - position[2])};
      const sph::Vec3 g = sph::local_boundary_share(grid, map.data(), 1.0f, level, h, local).gradient;
      const double c = static_cast<double>(w.mass) * p[i] / (static_cast<double>(rho[i]) * rho[i]) * K;
      force[0] += c * g.x, force[1] += c * g.y, force[2] += c * g.z;
      const double px = after[3 * i], pz = after[3 * i + 2];
      column += px > -0.13 && px < -0.07 && pz > -0.13 && pz < -0.07;
    }
    if (!dfsph) {  // step from the loads (contacts included), as the test
      sph_collider_loads l;
      check(sph_collider_loads_init(&l), "sph_collider_loads_init");
      check(sph_collider_get_loads(w.world, box, &l), "sph_collider_get_loads");
      if (frame >= frames - late) host_y += force[1] * dt, api_y += l.force.y * dt;
      force[0] = l.force.x, force[1] = l.force.y, force[2] = l.force.z;
    }
    force[1] -= mass * kGravity;
    for (int k = 0; k < 3; ++k) velocity[k] += force[k] / mass * dt, position[k] += velocity[k] * dt;
    sph_transform target = sph_transform_identity();
    target.position.x = static_cast<float>(position[0]);
    target.position.y = static_cast<float>(position[1]);
    target.position.z = static_cast<float>(position[2]);
    check(sph_collider_set_target_transform(w.world, box, &target), "sph_collider_set_target_transform");
    heights[frame] = position[1];
    if (frame >= frames - late) {
      water_level += column * (static_cast<double>(w.mass) / rho0) / (0.06 * 0.06) * dt;
      mean += position[1] * dt;
      late_time += dt;
    }
    x.swap(after);
  }
  water_level /= late_time, mean /= late_time;
  const double draft = water_level - (mean - kHalf);
  double early = 0.0, settled = 0.0;
  for (int frame = 500; frame < 1500; ++frame) early = std::fmax(early, std::fabs(heights[frame] - mean));
  for (int frame = frames - late; frame < frames; ++frame)
    settled = std::fmax(settled, std::fabs(heights[frame] - mean));
  std::printf(
      "floating box, backend %s, solver %s, %u particles: centre %.4f m, water level %.4f m (volume over the "
      "floor's square), draft %.2f cm (Archimedes %.2f cm, %+.1f %%), heave %.2f cm at 0.25-0.75 s, %.2f cm "
      "over the last second\n",
      backend_name, dfsph ? "dfsph" : "wcsph", n, mean, water_level, 100.0 * draft, 100.0 * archimedes,
      100.0 * (draft / archimedes - 1.0), 100.0 * early, 100.0 * settled);
  if (!dfsph)
    std::printf(
        "last second: the loads' vertical force %.4f N, the walls' reaction on the host %.4f N, the weight "
        "%.4f N\n",
        api_y / late_time, host_y / late_time, mass * kGravity);
  check(sph_sdf_destroy(tank_sdf), "sph_sdf_destroy");
  check(sph_sdf_destroy(box_sdf), "sph_sdf_destroy");
  check(support_world_close(&w), "support_world_close");
  return 0;
}
