// SPDX-License-Identifier: MIT
// The hydrostatic side wall of test_collider_loads.c (water of 10 x 14 x 10 lattice layers of 1 cm
// at rest in a tank whose face at x = 0 is a plane collider of its own; walls in the density) on
// either backend and either solver, the force summed on the host beside the loads feature (it
// was written when DFSPH worlds refused SPH_FEATURE_COLLIDER_LOADS; a world that refuses them
// is still measured without) (issue 17 item 5; docs/validation.md, "The submerged box per
// region").
//
//   physics_loads_side_wall [--backend cpu|cuda] [--solver wcsph|dfsph] [--step METRES] [--sample-every N]
//
// --step: the lattice step (default 0.01 m; docs/validation.md, "Loads against resolution"): the
// layers fill the same 10 x 14 x 10 cm (rounded to whole layers; H is then the lattice's volume
// over the tank's floor, 14 cm at 1 cm), h, the voxels and the frames scale with it (0.5 ms x step /
// 1 cm, over the same 0.4 s). --sample-every N: sum every Nth substep only (default 1). The last
// line, RESULT ..., is for scripts (scripts/loads-resolution).
//
// As physics_loads_breakdown: settled 0.8 s in frames of 20 ms, then 0.4 s in frames of 0.5 ms,
// one substep each; around each the positions before it and the densities and pressures after it,
// by particle id, and on the host the plane's walls' reaction m (p / rho^2) K grad Phi(x): the
// plane is flat over the tank, so Phi is the flat share of the solid x < -delta,
// spiky_half_space(x + delta, h), and the reaction's x part is m (p / rho^2) K Phi'(x + delta).
// The rest of the plane's force (its contacts; DFSPH's contact clamp) is bounded by the fluid's
// momentum balance: M g - dP/dt less the plane's and the tank's walls' reactions (the tank's map
// computed on the host) is what both colliders receive besides. With the loads (WCSPH) the plane's
// loads over the same substeps are printed beside it. References: rho0 g H^2 W / 2, and for WCSPH
// the resting compressible column's k rho0 (H - D) W (test_collider_loads.c).
#include <algorithm>
#include <chrono>
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
#include "physics/boundary_integrals.h"
#include "substep_reader.h"
#include "support.h"

namespace {

const double kGravity = 9.81, kStiffness = 100.0, kWidth = 0.1, kDepth = 0.14;

void check(sph_result r, const char* what) {
  if (r == SPH_OK) return;
  std::fprintf(stderr, "%s: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  const char* backend_name = "cpu";
  bool dfsph = false;
  double step = 0.01;
  int every = 1;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--backend") == 0 && k + 1 < argc)
      backend_name = argv[++k];
    else if (std::strcmp(argv[k], "--solver") == 0 && k + 1 < argc)
      dfsph = std::strcmp(argv[++k], "dfsph") == 0;
    else if (std::strcmp(argv[k], "--step") == 0 && k + 1 < argc)
      step = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--sample-every") == 0 && k + 1 < argc)
      every = std::max(1, std::atoi(argv[++k]));
    else {
      std::fprintf(
          stderr,
          "usage: %s [--backend cpu|cuda] [--solver wcsph|dfsph] [--step METRES] [--sample-every N]\n",
          argv[0]);
      return 2;
    }
  }
  if (!(step >= 0.002 && step <= 0.02)) {
    std::fprintf(stderr, "--step %g: give a lattice step between 0.002 and 0.02 m\n", step);
    return 2;
  }
  const auto started = std::chrono::steady_clock::now();
  const uint32_t across = static_cast<uint32_t>(std::lround(kWidth / step));
  const uint32_t layers[3] = {across, static_cast<uint32_t>(std::lround(kDepth / step)), across};
  const double width = kWidth;
  const double tank_min[3] = {-0.05, 0.0, 0.0}, tank_max[3] = {width, 2.0 * kDepth, width};
  float* lattice = nullptr;
  uint32_t n = 0;
  check(support_fcc_box(layers, step, nullptr, &lattice, &n), "support_fcc_box");
  // The water's depth: the lattice's volume (2 step^3 a point) over the tank's floor.
  const double depth = 2.0 * n * step * step * step / (width * width);
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = static_cast<float>(step * std::sqrt(2.0));
  def.capacity = n;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | SPH_FEATURE_COLLIDER_LOADS;
  if (dfsph) def.solver = SPH_SOLVER_DFSPH;
  support_world w;
  std::memset(&w, 0, sizeof w);
  bool loads = true;
  if (support_world_open(&w, support_backend_from_name(backend_name, SPH_BACKEND_CPU), &def, nullptr) !=
      SPH_OK) {
    support_world_close(&w);
    def.features &= ~SPH_FEATURE_COLLIDER_LOADS;  // a world that refuses the loads
    loads = false;
    check(support_world_open(&w, support_backend_from_name(backend_name, SPH_BACKEND_CPU), &def, nullptr),
          "support_world_open");
  }
  if (!dfsph) {
    w.params.stiffness = static_cast<float>(kStiffness);
    w.params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
    check(support_world_set_params(&w), "sph_world_set_params");
  }
  sph_sdf *tank_sdf = nullptr, *wall_sdf = nullptr;
  check(support_tank_between(w.context, w.world, tank_min, tank_max, 0.5 * step, 0.0f, &tank_sdf, nullptr),
        "support_tank_between");
  // The plane: the plane shape's solid y < 0 turned so that +y goes to +x (test_collider_loads.c's
  // add_axis_wall(axis 0, sign -1)): solid x < 0.
  sph_shape_desc shape;
  check(sph_shape_desc_init(&shape), "sph_shape_desc_init");
  shape.shape = SPH_SHAPE_PLANE;
  shape.half_extents.x = 0.3f, shape.half_extents.y = 0.05f, shape.half_extents.z = 0.3f;
  shape.voxel_size = static_cast<float>(step);
  check(sph_sdf_create_shape(w.context, &shape, &wall_sdf), "sph_sdf_create_shape");
  sph_collider_def collider;
  check(sph_collider_def_init(&collider), "sph_collider_def_init");
  collider.sdf = wall_sdf;
  collider.transform = sph_transform_identity();
  collider.transform.rotation.z = static_cast<float>(-std::sqrt(0.5));
  collider.transform.rotation.w = static_cast<float>(std::sqrt(0.5));
  sph_collider_id wall;
  check(sph_collider_create(w.world, &collider, &wall), "sph_collider_create");
  check(support_spawn(w.world, lattice, nullptr, n), "support_spawn");

  const float h = w.def.kernel_radius, rho0 = w.def.rest_density;
  const sph::BoundaryCalibration calibration = sph::fcc_boundary_calibration(w.def.particle_spacing, h);
  const double K = calibration.scale * w.mass, delta = calibration.offset;
  sph::ShapeSpec tank_spec;  // support_tank_between's inverted box, its map at +delta
  tank_spec.kind = sph::ShapeKind::Box;
  tank_spec.half_extents = sph::Vec3{static_cast<float>(0.5 * (tank_max[0] - tank_min[0])),
                                     static_cast<float>(0.5 * (tank_max[1] - tank_min[1])),
                                     static_cast<float>(0.5 * (tank_max[2] - tank_min[2]))};
  tank_spec.voxel_size = static_cast<float>(0.5 * step);
  const auto tank_asset = sph::build_shape_sdf(tank_spec, 1u << 24);
  const auto tank_map =
      sph::compute_boundary_map(*tank_asset, h, static_cast<float>(delta), sph::CpuParallel(2));
  const sph::SdfGridView tank_grid = tank_asset->host_view();
  const double tank_centre[3] = {0.5 * (tank_max[0] + tank_min[0]), 0.5 * (tank_max[1] + tank_min[1]),
                                 0.5 * (tank_max[2] + tank_min[2])};

  loads_sampling::SubstepReader reader(n);
  std::vector<float>&x = reader.start, &rho = reader.density, &p = reader.pressure;
  std::vector<float> velocity(x.size());
  uint64_t substeps = 0;  // all the world took, for the cost (particles x substeps)
  const auto step_counted = [&](float seconds) {
    check(sph_world_step(w.world, seconds), "sph_world_step");
    sph_stats stats;
    check(sph_stats_init(&stats), "sph_stats_init");
    check(sph_world_get_stats(w.world, &stats), "sph_world_get_stats");
    substeps += stats.substeps;
    return stats.substeps;
  };
  for (int frame = 0; frame < 40; ++frame) step_counted(0.02f);
  const float frame_time = static_cast<float>(0.0005 * step / 0.01);
  const int frames = static_cast<int>(std::lround(0.4 / frame_time));
  int samples = 0;
  uint32_t count = 0;
  double plane = 0.0, tank[3] = {0.0, 0.0, 0.0}, api = 0.0, api_time = 0.0, momentum[3] = {0.0, 0.0, 0.0};
  check(support_read_by_id(w.world, SPH_ATTRIBUTE_VELOCITY, velocity.data(), n, &count), "read velocities");
  for (uint32_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) momentum[k] -= static_cast<double>(w.mass) * velocity[3 * i + k];
  for (int frame = 0; frame < frames; ++frame) {
    const bool sampled = frame % every == 0;
    if (!reader.frame(w.world, sampled, frame, frame_time, step_counted)) return 1;
    if (!sampled) continue;
    count = reader.count;
    if (loads) {
      sph_collider_loads l;
      check(sph_collider_loads_init(&l), "sph_collider_loads_init");
      check(sph_collider_get_loads(w.world, wall, &l), "sph_collider_get_loads");
      api += l.force.x * l.frame_time, api_time += l.frame_time;
    }
    for (uint32_t i = 0; i < count; ++i) {
      const double c = static_cast<double>(w.mass) * p[i] / (static_cast<double>(rho[i]) * rho[i]) * K;
      plane += c * sph::spiky_half_space_slope<double>(x[3 * i] + delta, h);
      const sph::Vec3 local{static_cast<float>(x[3 * i] - tank_centre[0]),
                            static_cast<float>(x[3 * i + 1] - tank_centre[1]),
                            static_cast<float>(x[3 * i + 2] - tank_centre[2])};
      const sph::Vec3 g =
          sph::local_boundary_share(tank_grid, tank_map.data(), -1.0f, static_cast<float>(delta), h, local)
              .gradient;
      tank[0] += c * g.x, tank[1] += c * g.y, tank[2] += c * g.z;
    }
    reader.advance();
    ++samples;
  }
  check(support_read_by_id(w.world, SPH_ATTRIBUTE_VELOCITY, velocity.data(), n, &count), "read velocities");
  for (uint32_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) momentum[k] += static_cast<double>(w.mass) * velocity[3 * i + k];
  const double seconds = static_cast<double>(frame_time) * frames,
               weight = n * static_cast<double>(w.mass) * kGravity;
  const double push = -plane / samples;  // the fluid pushes the plane towards -x
  const double incompressible = rho0 * kGravity * depth * depth * width / 2.0;
  const double a = kGravity / kStiffness, column = std::log1p(a * depth) / a;
  const double compressible = kStiffness * rho0 * (depth - column) * width;
  double rest[3];
  const double walls[3] = {plane / samples + tank[0] / samples, tank[1] / samples, tank[2] / samples};
  for (int k = 0; k < 3; ++k) rest[k] = -(k == 1 ? weight : 0.0) - momentum[k] / seconds - walls[k];
  std::printf(
      "hydrostatic side wall, backend %s, solver %s, %u particles, step %.5f m, h %.4f m, H %.4f m: the "
      "plane's walls' reaction %.4f N: %+.2f %% of rho0 g H^2 W / 2 = %.4f N, %+.2f %% of the compressible "
      "column's %.4f N (k = %g)\n",
      backend_name, dfsph ? "dfsph" : "wcsph", n, step, static_cast<double>(h), depth, push,
      100.0 * (push / incompressible - 1.0), incompressible, 100.0 * (push / compressible - 1.0),
      compressible, kStiffness);
  std::printf(
      "momentum balance: both colliders' forces besides the walls' reactions (contacts, DFSPH's clamp) "
      "(%+.4f, %+.4f, %+.4f) N\n",
      rest[0], rest[1], rest[2]);
  if (loads)
    std::printf("the plane's loads over the same substeps: %.4f N (%+.2f %% of the compressible column's)\n",
                -api / api_time, 100.0 * (-api / api_time / compressible - 1.0));
  {
    // One line for scripts: force_err against each solver's reference (WCSPH: the compressible
    // column at k = 100, the test's; DFSPH: rho0 g H^2 W / 2).
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double incompressible_err = push / incompressible - 1.0,
                 compressible_err = push / compressible - 1.0;
    std::printf(
        "RESULT case=side_wall backend=%s solver=%s step=%.5f h=%.5f particles=%u substeps=%llu samples=%d "
        "force_err=%+.2f incompressible_err=%+.2f compressible_err=%+.2f depth=%.4f seconds=%.1f\n",
        backend_name, dfsph ? "dfsph" : "wcsph", step, static_cast<double>(h), n,
        static_cast<unsigned long long>(substeps), samples,
        100.0 * (dfsph ? incompressible_err : compressible_err), 100.0 * incompressible_err,
        100.0 * compressible_err, depth, seconds);
  }
  std::free(lattice);
  check(sph_sdf_destroy(tank_sdf), "sph_sdf_destroy");
  check(sph_sdf_destroy(wall_sdf), "sph_sdf_destroy");
  check(support_world_close(&w), "support_world_close");
  return 0;
}
