// SPDX-License-Identifier: MIT
// The floating box of test_collider_loads.c (a 10 cm cube of 500 kg/m^3 dropped from 1 cm above
// water 20 cm deep in a tank 30 cm square, spacing 2 cm, h = 3.6 cm, walls in the density) on
// either solver, stepped without the loads feature, so that DFSPH (whose worlds refuse the loads
// and the probes) can be measured (issue 17 item 5; docs/validation.md, "The submerged box per
// region").
//
//   physics_loads_floating_box [--backend cpu|cuda] [--solver wcsph|dfsph] [--step METRES]
//                              [--force host|loads] [--sample-every N] [--spawned]
//
// --spawned: the box starts at rest at Archimedes' draft (its bottom 5 cm below the fill's 20 cm), the
// fill's lattice cut the fill's wall margin around it, instead of dropped from 1 cm above the water.
// The program also prints the level by the particles' volume at their densities (m / max(rho, rho0)
// at the last sampled substep: the compression counted, the free surface's deficit not).
//
// --step: the lattice step, spacing / sqrt 2 (default 0.0141421 m, the 2 cm spacing;
// docs/validation.md, "Loads against resolution"): h, the voxels and the frames (0.5 ms x spacing /
// 2 cm) scale with it, the box, the tank and the water's 20 cm stay in metres. --force: what steps
// the body: the loads (WCSPH's default; DFSPH's loads came later, so there it is asked for) or the
// host's walls' reaction (DFSPH's default). --sample-every N (with the loads only): read back and
// sum only every Nth frame (the level, the host's sum; default 1), the cheap way at fine steps.
// The last line, RESULT ..., is for scripts (scripts/loads-resolution).
//
// Frames of 0.5 ms, one substep each, for 3 s. The fluid's force on the box per substep is summed
// on the host as physics_loads_breakdown does (the walls' reaction m (p / rho^2) K grad Phi_box at
// the substep's start, the box's map computed here); for WCSPH the loads (contacts included) step
// the body instead and the host's sum is printed beside them. The body moves in translation only
// (no rotation: the test's box stays level to within a few milliradians), by semi-implicit Euler
// each frame. The water level is the volume of the particles over a 6 x 6 cm square of the floor
// between the box and the tank's corner (2 cm from each) divided by its area (the test's gauge
// is refused on DFSPH); the draft is that level less the box's bottom, averaged over the last
// second, against Archimedes' 5 cm; and by the level the particles' volume gives, over the whole
// floor and (since session 16) with the film the walls' calibration keeps at every wall, and by a
// patched count of the square (each particle spread over its lattice column's step-wide square).
// At 1 cm the square's whole-particle count stands 1.4 cm above the patched count, which agrees
// with the film-corrected volume within 0.03 cm (docs/validation.md "Loads against resolution").
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
  bool dfsph = false, spawned = false;
  const char* force_from = nullptr;
  double step = 0.02 / std::sqrt(2.0);
  int every = 1;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--backend") == 0 && k + 1 < argc)
      backend_name = argv[++k];
    else if (std::strcmp(argv[k], "--solver") == 0 && k + 1 < argc)
      dfsph = std::strcmp(argv[++k], "dfsph") == 0;
    else if (std::strcmp(argv[k], "--step") == 0 && k + 1 < argc)
      step = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--force") == 0 && k + 1 < argc)
      force_from = argv[++k];
    else if (std::strcmp(argv[k], "--sample-every") == 0 && k + 1 < argc)
      every = std::max(1, std::atoi(argv[++k]));
    else if (std::strcmp(argv[k], "--spawned") == 0)
      spawned = true;
    else {
      std::fprintf(
          stderr,
          "usage: %s [--backend cpu|cuda] [--solver wcsph|dfsph] [--step METRES] [--force host|loads] "
          "[--sample-every N] [--spawned]\n",
          argv[0]);
      return 2;
    }
  }
  const bool from_loads = force_from ? std::strcmp(force_from, "loads") == 0 : !dfsph;
  if (!(step >= 0.002 && step <= 0.02) ||
      (force_from && !from_loads && std::strcmp(force_from, "host") != 0) || (every > 1 && !from_loads)) {
    std::fprintf(stderr,
                 "give a --step between 0.002 and 0.02 m, --force host or loads, --sample-every with "
                 "--force loads only\n");
    return 2;
  }
  const auto started = std::chrono::steady_clock::now();
  const double spacing = step * std::sqrt(2.0), scale = spacing / 0.02;  // 1 at the default
  // The box's voxels: about spacing / 2, a whole number across its half side (5 of 1 cm at the default),
  // so that its faces lie on samples, where the trilinear field's zero level is exact.
  const double box_voxel = kHalf / std::max(1.0, std::round(kHalf / (0.01 * scale)));
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = static_cast<float>(spacing);
  // fill_box's 0.018 m^3 at 2 step^3 a particle (3182 at the default), with room.
  def.capacity = std::max(8000u, static_cast<uint32_t>(1.5 * 0.018 / (2.0 * step * step * step)));
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | (from_loads ? SPH_FEATURE_COLLIDER_LOADS : 0u);
  if (dfsph) def.solver = SPH_SOLVER_DFSPH;
  support_world w;
  std::memset(&w, 0, sizeof w);
  check(support_world_open(&w, support_backend_from_name(backend_name, SPH_BACKEND_CPU), &def, nullptr),
        "support_world_open");
  const support_tank tank = {
      {0.0f, 0.25f, 0.0f}, {0.15f, 0.25f, 0.15f}, static_cast<float>(0.01 * scale), 0.0f};
  sph_sdf *tank_sdf = nullptr, *box_sdf = nullptr;
  check(support_tank_create(w.context, w.world, &tank, &tank_sdf, nullptr), "support_tank_create");
  sph_shape_desc shape;
  check(sph_shape_desc_init(&shape), "sph_shape_desc_init");
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = static_cast<float>(kHalf);
  shape.voxel_size = static_cast<float>(box_voxel);
  shape.padding_voxels = 8;
  check(sph_sdf_create_shape(w.context, &shape, &box_sdf), "sph_sdf_create_shape");
  const double mass = 500.0 * 8.0 * kHalf * kHalf * kHalf, archimedes = mass / (1000.0 * 4.0 * kHalf * kHalf);
  // --spawned: the box at rest at Archimedes' draft in the fill, the fill's
  // lattice cut step / 2 around it, instead of dropped from 1 cm above the water.
  double position[3] = {0.0, spawned ? kDepth - archimedes + kHalf : kDepth + kHalf + 0.01, 0.0},
         velocity[3] = {0.0, 0.0, 0.0};
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
  if (!spawned) {
    check(sph_world_fill_box(w.world, &water, nullptr), "sph_world_fill_box");
  } else {
    const float s = static_cast<float>(spacing);
    const double gap = 0.5 * spacing, grown = kHalf + gap;  // sph_world_fill_box's margin
    const auto points = sph::fcc_points_in_box(sph::Vec3{water.min.x, water.min.y, water.min.z},
                                               sph::Vec3{water.max.x, water.max.y, water.max.z}, s);
    std::vector<float> kept;
    for (const sph::Vec3& q : points)
      if (!(std::fabs(q.x - position[0]) < grown && std::fabs(q.y - position[1]) < grown &&
            std::fabs(q.z - position[2]) < grown))
        kept.insert(kept.end(), {q.x, q.y, q.z});
    check(support_spawn(w.world, kept.data(), nullptr, static_cast<uint32_t>(kept.size() / 3)),
          "support_spawn");
  }

  const float h = w.def.kernel_radius, rho0 = w.def.rest_density;
  const sph::BoundaryCalibration calibration = sph::fcc_boundary_calibration(w.def.particle_spacing, h);
  const double K = calibration.scale * w.mass;
  const float level = -static_cast<float>(calibration.offset);
  sph::ShapeSpec spec;
  spec.kind = sph::ShapeKind::Box;
  spec.half_extents =
      sph::Vec3{static_cast<float>(kHalf), static_cast<float>(kHalf), static_cast<float>(kHalf)};
  spec.voxel_size = static_cast<float>(box_voxel);
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
  const double dt = 0.0005 * scale;
  const int frames = static_cast<int>(std::lround(3.0 / dt)), late = static_cast<int>(std::lround(1.0 / dt));
  std::vector<double> heights(frames);
  double water_level = 0.0, mean = 0.0, host_y = 0.0, api_y = 0.0, late_time = 0.0, sampled_time = 0.0;
  uint32_t count = 0;
  uint64_t substeps = 0;    // all the world took, for the cost (particles x substeps)
  bool have_start = false;  // x holds the next substep's start
  // The square's gauge counts whole particles: on a lattice whose columns stand a step apart, a
  // square a few steps wide holds one column more or less per axis as the lattice shifts against
  // its edges (1/6 of its count at 1 cm). The patched count spreads each particle over the square
  // patch of one step its lattice column stands for (a particle's volume 2 step^3 over step^2 of
  // floor, two layers a column) and counts the part of it inside the square: the same level
  // without that sensitivity.
  const auto overlap = [step](double c) {
    const double lo = std::fmax(c - 0.5 * step, -0.13), hi = std::fmin(c + 0.5 * step, -0.07);
    return hi > lo ? (hi - lo) / step : 0.0;
  };
  double patched_level = 0.0;
  for (int frame = 0; frame < frames; ++frame) {
    const bool sampled = frame % every == 0;
    if (sampled && !have_start)
      check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, x.data(), n, &count), "read positions");
    check(sph_world_step(w.world, static_cast<float>(dt)), "sph_world_step");
    check(sph_world_get_stats(w.world, &stats), "sph_world_get_stats");
    substeps += stats.substeps;
    if (stats.substeps != 1) {
      std::fprintf(stderr, "frame %d took %u substeps, not 1\n", frame, stats.substeps);
      return 1;
    }
    have_start = false;
    double force[3] = {0.0, 0.0, 0.0}, column = 0.0, patched = 0.0;
    if (sampled) {
      check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, after.data(), n, &count), "read positions");
      check(support_read_by_id(w.world, SPH_ATTRIBUTE_DENSITY, rho.data(), n, &count), "read densities");
      check(support_read_by_id(w.world, SPH_ATTRIBUTE_PRESSURE, p.data(), n, &count), "read pressures");
    }
    // The walls' reaction at the substep's start, the box at its pose then (the last frame's end).
    for (uint32_t i = 0; sampled && i < count; ++i) {
      const sph::Vec3 local{static_cast<float>(x[3 * i] - position[0]),
                            static_cast<float>(x[3 * i + 1] - position[1]),
                            static_cast<float>(x[3 * i + 2] - position[2])};
      const sph::Vec3 g = sph::local_boundary_share(grid, map.data(), 1.0f, level, h, local).gradient;
      const double c = static_cast<double>(w.mass) * p[i] / (static_cast<double>(rho[i]) * rho[i]) * K;
      force[0] += c * g.x, force[1] += c * g.y, force[2] += c * g.z;
      const double px = after[3 * i], pz = after[3 * i + 2];
      column += px > -0.13 && px < -0.07 && pz > -0.13 && pz < -0.07;
      patched += overlap(px) * overlap(pz);
    }
    if (from_loads) {  // step from the loads (contacts included), as the test
      sph_collider_loads l;
      check(sph_collider_loads_init(&l), "sph_collider_loads_init");
      check(sph_collider_get_loads(w.world, box, &l), "sph_collider_get_loads");
      if (frame >= frames - late && sampled) host_y += force[1] * dt, api_y += l.force.y * dt;
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
      if (sampled) water_level += column * (static_cast<double>(w.mass) / rho0) / (0.06 * 0.06) * dt;
      if (sampled) patched_level += patched * (static_cast<double>(w.mass) / rho0) / (0.06 * 0.06) * dt;
      mean += position[1] * dt;
      late_time += dt;
      sampled_time += sampled ? dt : 0.0;
    }
    if (sampled) x.swap(after), have_start = true;
  }
  water_level /= sampled_time, mean /= late_time, patched_level /= sampled_time;
  const double draft = water_level - (mean - kHalf);
  // A second level that no gauge's packing moves: the particles' volume at rho0 (m / rho0 each) and the
  // box's part below the level fill the tank's 30 x 30 cm floor, N v + A_box (L - bottom) = A_tank L.
  const double volume_level =
      (n * static_cast<double>(w.mass) / rho0 - 0.01 * (mean - kHalf)) / (0.09 - 4.0 * kHalf * kHalf);
  const double volume_draft = volume_level - (mean - kHalf);
  // The same with the film the walls' calibration keeps free of water at every wall, (spacing -
  // step) / 2 (docs/validation.md, "Loads on a hydrostatic tank's side wall"): the water stands on
  // the floor's film, within the tank's walls' and outside the box's (grown by it):
  // N v = (0.3 - 2 f)^2 (L - f) - (0.1 + 2 f)^2 (L - (bottom - f)).
  const double film = 0.5 * (spacing - step), bottom = mean - kHalf;
  const double inner = (0.3 - 2.0 * film) * (0.3 - 2.0 * film),
               grown = (0.1 + 2.0 * film) * (0.1 + 2.0 * film);
  const double film_level =
      (n * static_cast<double>(w.mass) / rho0 + inner * film - grown * (bottom - film)) / (inner - grown);
  double early = 0.0, settled = 0.0;
  for (int frame = static_cast<int>(std::lround(0.25 / dt)); frame < std::lround(0.75 / dt); ++frame)
    early = std::fmax(early, std::fabs(heights[frame] - mean));
  for (int frame = frames - late; frame < frames; ++frame)
    settled = std::fmax(settled, std::fabs(heights[frame] - mean));
  std::printf(
      "floating box, backend %s, solver %s, %u particles: centre %.4f m, water level %.4f m (volume over the "
      "floor's square), draft %.2f cm (Archimedes %.2f cm, %+.1f %%), heave %.2f cm at 0.25-0.75 s, %.2f cm "
      "over the last second; by the volume's level %.4f m the draft %.2f cm (%+.1f %%)\n",
      backend_name, dfsph ? "dfsph" : "wcsph", n, mean, water_level, 100.0 * draft, 100.0 * archimedes,
      100.0 * (draft / archimedes - 1.0), 100.0 * early, 100.0 * settled, volume_level, 100.0 * volume_draft,
      100.0 * (volume_draft / archimedes - 1.0));
  {
    // The volume's level with the compression, each particle's
    // m / max(rho, rho0) at the last sampled substep (the free surface's summation deficit not counted).
    double compressed = 0.0;
    for (uint32_t i = 0; i < count; ++i)
      compressed +=
          static_cast<double>(w.mass) / std::fmax(static_cast<double>(rho[i]), static_cast<double>(rho0));
    const double level_c = (compressed - 0.01 * (mean - kHalf)) / (0.09 - 4.0 * kHalf * kHalf);
    std::printf("the particles' volume at their densities: level %.4f m, draft %.2f cm (%+.1f %%)\n", level_c,
                100.0 * (level_c - (mean - kHalf)), 100.0 * ((level_c - (mean - kHalf)) / archimedes - 1.0));
  }
  std::printf(
      "the particles' volume with the walls' films (%.2f mm): level %.4f m, draft %.2f cm (%+.1f %%)\n",
      1000.0 * film, film_level, 100.0 * (film_level - bottom),
      100.0 * ((film_level - bottom) / archimedes - 1.0));
  std::printf(
      "the square's patched count (each particle spread over a step's square): level %.4f m, draft %.2f cm "
      "(%+.1f %%)\n",
      patched_level, 100.0 * (patched_level - (mean - kHalf)),
      100.0 * ((patched_level - (mean - kHalf)) / archimedes - 1.0));
  if (from_loads)
    std::printf(
        "last second: the loads' vertical force %.4f N, the walls' reaction on the host %.4f N, the weight "
        "%.4f N\n",
        api_y / sampled_time, host_y / sampled_time, mass * kGravity);
  std::printf(
      "RESULT case=floating_box backend=%s solver=%s step=%.5f h=%.5f particles=%u substeps=%llu force=%s "
      "draft_err=%+.2f draft_cm=%.3f level=%.4f volume_draft_err=%+.2f volume_level=%.4f heave_early_cm=%.2f "
      "heave_late_cm=%.2f seconds=%.1f\n",
      backend_name, dfsph ? "dfsph" : "wcsph", step, static_cast<double>(h), n,
      static_cast<unsigned long long>(substeps), from_loads ? "loads" : "host",
      100.0 * (draft / archimedes - 1.0), 100.0 * draft, water_level,
      100.0 * (volume_draft / archimedes - 1.0), volume_level, 100.0 * early, 100.0 * settled,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  check(sph_sdf_destroy(tank_sdf), "sph_sdf_destroy");
  check(sph_sdf_destroy(box_sdf), "sph_sdf_destroy");
  check(support_world_close(&w), "support_world_close");
  return 0;
}
