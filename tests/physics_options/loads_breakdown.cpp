// SPDX-License-Identifier: MIT
// The submerged box of test_collider_loads.c (a 6 cm cube fixed with its centre 8 cm above the floor
// of a tank 16 x 16 cm filled to 20 cm, lattice step 1 cm, h = 2.5 cm), its walls' pressure
// reaction broken down per face, edge and corner region, on either backend and either solver
// (issue 17 item 5: which part of the buoyancy's error comes from where; docs/validation.md,
// "The submerged box per region").
//
//   physics_loads_breakdown [--backend cpu|cuda] [--solver wcsph|dfsph] [--dt-max SECONDS]
//                           [--settle SECONDS] [--perturb SEED] [--frames N] [--check-loads]
//                           [--self-check | --self-check-only] [--step METRES] [--sample-every N]
//                           [--box-voxel METRES] [--initial-densities] [--full-first-layer]
//                           [--centre-y METRES]
//
// --centre-y: the box's centre height (default 0.08 m). With the box through the free surface (0.19:
// its top 2 cm above the water) the program also prints the water's level by its volume (each
// particle's m / max(rho, rho0) over the tank less the box), the hydrostatic level and the level the
// box's force stands for (bottom + F / (rho0 g A)): a floating box's draft without its dynamics
// (docs/validation.md, "Session 18: a finite solid's share that keeps its size").
// --initial-densities: print rho / rho0 of the lattice as spawned (one 1 us substep without gravity)
// at the box's first layer per region and at the tank's floor away from the box, then stop: the
// walls' share beside a finite solid against a flat wall's (docs/validation.md, "Session 17: the
// step / 2 placement again"). --full-first-layer: cut the lattice a quarter step beyond the box's
// faces instead of the test's half step, which float rounding makes drop the first layer below three
// of its faces.
//
// --step: the lattice step (default 0.01 m; issue 17, "Loads against resolution" in
// docs/validation.md): the layers fill the same tank (16 x 20 x 16 cm rounded to whole layers), h,
// the voxels (the box's: a whole number across its half side) and the window's substeps scale with it (frames
// of 0.5 ms x step / 1 cm), the box and the tank stay in metres. --frames: the window's substeps (default 0.4
// s of them, 800 at 1 cm);
// --sample-every N: read back and sum only every Nth of them (default 1; the others are stepped
// unread, a cheaper average of the same window at fine steps). The last line, RESULT ..., is for
// scripts (scripts/loads-resolution). --check-loads: fail unless the loads on the box
// equal the host's sum of its walls' reaction over the substeps that end with no particle on its
// surface (at least half of them) and the loads on both colliders the fluid's momentum change
// (M g - dP/dt) over all of them, each within 1e-3 N (the ctest physics_loads_breakdown_dfsph).
//
// --box-voxel: the box's SDF voxel (default: about step / 2, a whole number across its half side, so
// that its faces lie on samples); 0.0055 at the default step puts its faces between samples, as a
// user's box usually is (docs/validation.md, "The submerged box: particles resting on a box whose
// faces lie between samples").
//
// --perturb moves every lattice point by up to 1e-7 m (uniform per axis, a generator seeded with
// SEED): a change of the size of a float's rounding, to see how far the box's settled state
// depends on it (a CPU/CUDA difference is of that size).
//
// The world is made and stepped through the C API as in the test (walls in the density; WCSPH:
// ideal gas k = 100 with the acoustic step limit; DFSPH: its defaults, dt_max 1 ms unless given):
// (--self-check: first one substep of 0.5 ms from the lattice, below), 0.8 s (--settle) in frames of 20 ms,
// then 0.4 s in frames of 0.5 ms, one substep each. Around each of those the program reads back, by particle
// id, the positions before it (the substep's start) and the densities and pressures after it (its density
// pass's, at those positions), and evaluates on the host, per particle, the box's share of the wall's
// reaction,
//   F_i = m (p_i / rho_i^2) K grad Phi_box(x_i)         (boundary_density.h),
// the impulse the solvers' wall force gives the box over the substep, divided by dt; exact for
// WCSPH (the loads pass's own sum), and for DFSPH the reaction of what both solves applied
// (p = (k + k_v / dt) rho^2). The box's density map is computed here from the same shape
// (cpu_boundary_maps.h). --self-check: in the first substep no particle touches the box yet, so with
// SPH_FEATURE_COLLIDER_LOADS the loads are the walls' reaction alone (WCSPH; on DFSPH the contact
// clamp already acts there, 54 N of the box's -1356 N along x and z, so the two differ by it; with
// the clamp's impulses left out of the loads they agreed within 1.3e-4 N, docs/validation.md) and
// the two are printed side by side (on the CPU they agree to the last printed digit; on CUDA they
// show whether the device's map is the host's). --self-check-only stops there and fails unless
// they agree within 1e-5 of the force (the ctest physics_loads_breakdown_self_check, WCSPH; the backend
// defaults to SPH_TEST_BACKEND's, so the GPU test script runs it on CUDA). A particle's region is the set of
// the box's axes it lies beyond at the substep's start: one axis a face (top, bottom, sides), two an edge
// (top, bottom, vertical), three a corner (top, bottom), none "inside the box" (particles the collision
// response left caught inside an edge, where the trilinear SDF is flat; none since its push-out
// reaches the surface, docs/validation.md "The submerged box: particles caught inside its edges"). With the
// loads, the contacts are the loads less the walls' reaction over the same substeps; "contacts" per region
// counts the particles that end a substep on or in the box's surface (those the response touched).
// Momentum balance: the fluid's dP/dt = M g less the colliders' forces, so with the tank's walls'
// reaction also summed on the host (its map computed here too), M g - dP/dt - both walls' reactions
// is what the colliders receive besides the walls' reaction: the contacts, and for DFSPH the
// impulses of its contact clamp (respect_contact), which the loads include. With the loads the same
// from the loads is printed as a check.
//
// Also per region: the particles within h of the box, their mean rho / rho0 and their pressure
// against rho0 g d, d their depth below the hydrostatic level (y + p / (rho0 g) averaged over the
// interior: particles more than h from every wall and 5 cm below the top lattice plane); and the
// interior's p / (rho0 g d) from 3 cm below that plane down, the profile the walls see. Each face's
// wall reaction is compared with rho0 g d A at the face's depth (the faces' regions alone, and with
// the adjoining edges and corners). BREAKDOWN_DEBUG=1 first prints the host map along the top face's
// normal (K Phi(spacing / 2) must be the calibration's 23.1 % of rho0).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "box_regions.h"
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

using namespace loads_breakdown;  // NOLINT: the regions' names (box_regions.h)

const double kGravity = 9.81, kSide = 0.16, kFill = 0.2;
double kCentre[3] = {0.08, 0.08, 0.08};  // --centre-y sets the height

void check(sph_result r, const char* what) {
  if (r == SPH_OK) return;
  std::fprintf(stderr, "%s: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
  std::exit(1);
}

struct Tally {
  double force[3] = {0.0, 0.0, 0.0};  // N, summed over samples
  double normal = 0.0;                // N, the side faces' inward push (sum of |F| along their normal)
  double density = 0.0, pressure_ratio = 0.0;
  double count = 0.0, near = 0.0;
  double contacts = 0.0;  // particles on the box's surface after a substep (the collision response's)
};

}  // namespace

int main(int argc, char** argv) {
  const char* backend_name = sph_test_backend_name();  // SPH_TEST_BACKEND, unset: cpu
  bool dfsph = false, self_check = false, only = false, check_loads = false, initial = false,
       full_first_layer = false;
  int frames = 0, every = 1;
  double settle_time = 0.8, step = 0.01;
  unsigned long perturb = 0;
  double dt_max = 0.0, box_voxel_arg = 0.0;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--backend") == 0 && k + 1 < argc)
      backend_name = argv[++k];
    else if (std::strcmp(argv[k], "--solver") == 0 && k + 1 < argc)
      dfsph = std::strcmp(argv[++k], "dfsph") == 0;
    else if (std::strcmp(argv[k], "--dt-max") == 0 && k + 1 < argc)
      dt_max = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--settle") == 0 && k + 1 < argc)
      settle_time = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--perturb") == 0 && k + 1 < argc)
      perturb = std::strtoul(argv[++k], nullptr, 10);
    else if (std::strcmp(argv[k], "--self-check") == 0)
      self_check = true;
    else if (std::strcmp(argv[k], "--frames") == 0 && k + 1 < argc)
      frames = std::max(1, std::atoi(argv[++k]));
    else if (std::strcmp(argv[k], "--step") == 0 && k + 1 < argc)
      step = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--sample-every") == 0 && k + 1 < argc)
      every = std::max(1, std::atoi(argv[++k]));
    else if (std::strcmp(argv[k], "--box-voxel") == 0 && k + 1 < argc)
      box_voxel_arg = std::atof(argv[++k]);
    else if (std::strcmp(argv[k], "--check-loads") == 0)
      check_loads = true;
    else if (std::strcmp(argv[k], "--self-check-only") == 0)
      self_check = only = true;
    else if (std::strcmp(argv[k], "--initial-densities") == 0)
      initial = true;
    else if (std::strcmp(argv[k], "--full-first-layer") == 0)
      full_first_layer = true;
    else if (std::strcmp(argv[k], "--centre-y") == 0 && k + 1 < argc)
      kCentre[1] = std::atof(argv[++k]);
    else {
      std::fprintf(
          stderr,
          "usage: %s [--backend cpu|cuda] [--solver wcsph|dfsph] [--dt-max SECONDS] [--settle "
          "SECONDS] [--perturb SEED] [--frames N] [--check-loads] [--self-check | --self-check-only] [--step "
          "METRES] [--sample-every N] [--box-voxel METRES] [--initial-densities] [--full-first-layer] "
          "[--centre-y METRES]\n",
          argv[0]);
      return 2;
    }
  }
  if (!(step >= 0.002 && step <= 0.02) || (check_loads && every > 1) ||
      !(box_voxel_arg == 0.0 || (box_voxel_arg >= 0.001 && box_voxel_arg <= 0.02)) ||
      !(kCentre[1] >= 0.05 && kCentre[1] <= 0.3)) {
    // --check-loads compares the momentum over the whole window with the sampled substeps' loads.
    std::fprintf(stderr,
                 "--step %g, --box-voxel %g, --centre-y %g: give a lattice step between 0.002 and 0.02 m, a "
                 "box voxel between 0.001 and 0.02 m, a centre between 0.05 and 0.3 m (inside the 0.4 m "
                 "tank, above its floor) (and --check-loads without --sample-every)\n",
                 step, box_voxel_arg, kCentre[1]);
    return 2;
  }
  const sph_backend backend = support_backend_from_name(backend_name, SPH_BACKEND_CPU);
  // The box's voxels: about step / 2, a whole number of them across its half side, so that its faces
  // lie on samples as at 1 cm (6 of 5 mm), where the trilinear field's zero level is exact.
  const double box_voxel =
      box_voxel_arg > 0.0 ? box_voxel_arg : kHalf / std::max(1.0, std::round(kHalf / (0.5 * step)));
  const auto started = std::chrono::steady_clock::now();

  // The scene of test_collider_loads.c's submerged_box_force.
  const uint32_t side_layers = static_cast<uint32_t>(std::lround(kSide / step)),
                 layers[3] = {side_layers, static_cast<uint32_t>(std::lround(kFill / step)), side_layers};
  float* lattice = nullptr;
  uint32_t n = 0, kept = 0;
  check(support_fcc_box(layers, step, nullptr, &lattice, &n), "support_fcc_box");
  // The test's cut, kHalf + step / 2, drops by float rounding the layer step / 2 below the box's bottom,
  // -x and -z faces (|0.045f - 0.08| < 0.035): those faces start 1.5 steps from the water. With
  // --full-first-layer the cut lies a quarter step beyond the faces and keeps that layer.
  const double cut = kHalf + (full_first_layer ? 0.25 : 0.5) * step;
  for (uint32_t i = 0; i < n; ++i) {
    bool inside = true;
    for (int k = 0; k < 3; ++k) inside = inside && std::fabs(lattice[3 * i + k] - kCentre[k]) < cut;
    if (inside) continue;
    std::memmove(lattice + 3 * kept, lattice + 3 * i, 3 * sizeof(float));
    ++kept;
  }
  if (perturb != 0) support_nudge(lattice, kept, perturb, 1e-7);
  sph_world_def def;
  sph_world_def_init(&def);
  def.particle_spacing = static_cast<float>(step * std::sqrt(2.0));
  def.capacity = kept;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY | SPH_FEATURE_COLLIDER_LOADS;
  if (dfsph) def.solver = SPH_SOLVER_DFSPH;
  support_world w;
  std::memset(&w, 0, sizeof w);
  bool loads = true;
  if (support_world_open(&w, backend, &def, nullptr) != SPH_OK) {
    support_world_close(&w);
    def.features &= ~SPH_FEATURE_COLLIDER_LOADS;  // a backend that refuses the loads on DFSPH
    loads = false;
    check(support_world_open(&w, backend, &def, nullptr), "support_world_open");
  }
  sph_world_params params = w.params;
  if (!dfsph) params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  if (dt_max > 0.0) params.dt_max = static_cast<float>(dt_max);
  w.params = params;
  check(support_world_set_params(&w), "sph_world_set_params");
  const double tank_min[3] = {0.0, 0.0, 0.0}, tank_max[3] = {kSide, 0.4, kSide};
  sph_sdf *tank_sdf = nullptr, *box_sdf = nullptr;
  sph_collider_id tank;
  check(support_tank_between(w.context, w.world, tank_min, tank_max, 0.5 * step, 0.0f, &tank_sdf, &tank),
        "support_tank_between");
  sph_shape_desc shape;
  check(sph_shape_desc_init(&shape), "sph_shape_desc_init");
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = static_cast<float>(kHalf);
  shape.voxel_size = static_cast<float>(box_voxel);
  shape.padding_voxels = 8;
  check(sph_sdf_create_shape(w.context, &shape, &box_sdf), "sph_sdf_create_shape");
  sph_collider_def collider;
  check(sph_collider_def_init(&collider), "sph_collider_def_init");
  collider.sdf = box_sdf;
  collider.transform = sph_transform_identity();
  collider.transform.position.x = static_cast<float>(kCentre[0]);
  collider.transform.position.y = static_cast<float>(kCentre[1]);
  collider.transform.position.z = static_cast<float>(kCentre[2]);
  sph_collider_id box;
  check(sph_collider_create(w.world, &collider, &box), "sph_collider_create");
  check(support_spawn(w.world, lattice, nullptr, kept), "support_spawn");

  // The box's map on the host, from the same shape (api_sdf.cpp's conversion) and the world's
  // calibration (BoundaryDensity::make_constants): K = m scale, the solid moved delta into it.
  const float h = w.def.kernel_radius, spacing = w.def.particle_spacing, rho0 = w.def.rest_density;
  sph::ShapeSpec spec;
  spec.kind = sph::ShapeKind::Box;
  spec.half_extents =
      sph::Vec3{static_cast<float>(kHalf), static_cast<float>(kHalf), static_cast<float>(kHalf)};
  spec.voxel_size = static_cast<float>(box_voxel);
  spec.padding_voxels = 8;
  const auto asset = sph::build_shape_sdf(spec, 1u << 24);
  const sph::BoundaryCalibration calibration = sph::fcc_boundary_calibration(spacing, h);
  const float K = static_cast<float>(calibration.scale * w.mass);
  const float level = -static_cast<float>(calibration.offset);  // a solid (sign +1) counts {phi < -delta}
  const auto map = sph::compute_boundary_map(*asset, h, level, sph::CpuParallel(2));
  const sph::SdfGridView grid = asset->host_view();
  double tank_walls[3] = {0.0, 0.0, 0.0}, tank_loads[3] = {0.0, 0.0, 0.0}, momentum[3] = {0.0, 0.0, 0.0};

  if (std::getenv("BREAKDOWN_DEBUG")) {
    for (double d : {0.0, 0.0035, 0.00707, 0.0141, 0.02}) {
      const sph::Vec3 at{0.0f, static_cast<float>(kHalf + d), 0.0f};
      const sph::LocalBoundaryShare s = sph::local_boundary_share(grid, map.data(), 1.0f, level, h, at);
      // Beside it the flat wall's (the half space below the face moved delta into the box).
      const double flat = d + calibration.offset;
      std::printf(
          "debug: d %.4f distance %.5f K Phi %.2f K grad Phi (%.1f, %.1f, %.1f); a flat wall's K Phi %.2f, "
          "K dPhi/dd %.1f\n",
          d, static_cast<double>(sph::sample_distance(grid, at)), static_cast<double>(K * s.share),
          static_cast<double>(K * s.gradient.x), static_cast<double>(K * s.gradient.y),
          static_cast<double>(K * s.gradient.z), K * sph::spiky_half_space<double>(flat, h),
          K * sph::spiky_half_space_slope<double>(flat, h));
    }
  }
  const double expected = rho0 * kGravity * 8.0 * kHalf * kHalf * kHalf, area = 4.0 * kHalf * kHalf;
  Tally tally[kRegions];
  double interior_ratio = 0.0, interior_count = 0.0, level_sum = 0.0, plane_sum = 0.0;
  double api[3] = {0.0, 0.0, 0.0}, api_time = 0.0;
  // --check-loads' per-box comparison runs over the substeps that end with no particle on the box's
  // surface: the loads there hold the walls' reaction alone (the contacts' share is what separates
  // the two elsewhere, and no independent measure of it exists on the host).
  double clear_api[3] = {0.0, 0.0, 0.0}, clear_host[3] = {0.0, 0.0, 0.0}, clear_time = 0.0;
  int clear_samples = 0;
  int samples = 0;
  loads_sampling::SubstepReader reader(kept);
  std::vector<float>&x = reader.start, &after = reader.end, &rho = reader.density, &p = reader.pressure;
  // Settle 0.8 s (--settle) in frames of 20 ms, then 0.4 s in frames of 0.5 ms (at 1 cm; both limits scale
  // with h): one substep each (the step limits allow 1 ms), so the positions read before a frame are its
  // substep's start, where the density pass put the pressures and densities read after it.
  const int settle = static_cast<int>(std::lround(settle_time / 0.02));
  const float frame_time = static_cast<float>(0.0005 * step / 0.01);
  if (frames == 0) frames = static_cast<int>(std::lround(0.4 / frame_time));
  uint64_t substeps = 0;  // all the world took, for the cost (particles x substeps)
  const auto step_counted = [&](float seconds) {
    check(sph_world_step(w.world, seconds), "sph_world_step");
    sph_stats stats;
    check(sph_stats_init(&stats), "sph_stats_init");
    check(sph_world_get_stats(w.world, &stats), "sph_world_get_stats");
    substeps += stats.substeps;
    return stats.substeps;
  };
  // --initial-densities: the lattice as spawned, one substep of 1 us without gravity, so the densities
  // are the spawn positions' (as test_boundary_density.c reads a block's): rho / rho0 of the box's
  // first layer (particles within a step of it) per region, and of the tank's first layer away from
  // the box (the flat walls' reference).
  if (initial) {
    check(support_set_gravity_and_steps(w.world, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-6f), "set gravity");
    check(sph_world_step(w.world, 1e-6f), "sph_world_step");
    uint32_t c0 = 0;
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, x.data(), kept, &c0), "read positions");
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_DENSITY, rho.data(), kept, &c0), "read densities");
    double sum[kRegions + 1] = {}, lo[kRegions + 1], hi[kRegions + 1], count[kRegions + 1] = {};
    for (int r = 0; r <= kRegions; ++r) lo[r] = 1e9, hi[r] = -1e9;
    for (uint32_t i = 0; i < c0; ++i) {
      const double local[3] = {x[3 * i] - kCentre[0], x[3 * i + 1] - kCentre[1], x[3 * i + 2] - kCentre[2]};
      double beyond = 0.0;  // the largest distance beyond a face, per axis (the first layer: step / 2)
      for (int k = 0; k < 3; ++k) beyond = std::fmax(beyond, std::fabs(local[k]) - kHalf);
      const double wall =
          std::fmin(std::fmin(x[3 * i], kSide - x[3 * i]), std::fmin(x[3 * i + 2], kSide - x[3 * i + 2]));
      int r = -1;
      if (beyond < step)
        r = region_of(local);
      else if (x[3 * i + 1] < step && wall > h && beyond > h)
        r = kRegions;  // the floor, away from all else
      if (r < 0) continue;
      const double v = rho[i] / rho0;
      sum[r] += v, count[r] += 1.0, lo[r] = std::fmin(lo[r], v), hi[r] = std::fmax(hi[r], v);
    }
    std::printf(
        "initial densities (the lattice as spawned, no gravity), K %.1f kg/m^3, delta %.4f m: first layer "
        "rho / rho0 mean [min, max] (particles)\n",
        static_cast<double>(K), calibration.offset);
    for (int r = 0; r <= kRegions; ++r)
      if (count[r] > 0.0)
        std::printf("  %-15s %.4f [%.4f, %.4f] (%.0f)\n", r < kRegions ? kRegionNames[r] : "tank floor",
                    sum[r] / count[r], lo[r], hi[r], count[r]);
    support_world_close(&w);
    return 0;
  }
  // The self-check: the first substep from the lattice has no contacts yet, so with the loads on its
  // loads are the walls' reaction alone, which the host's map must reproduce.
  if (self_check) {
    uint32_t c0 = 0;
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_POSITION, x.data(), kept, &c0), "read positions");
    step_counted(frame_time);
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_DENSITY, rho.data(), kept, &c0), "read densities");
    check(support_read_by_id(w.world, SPH_ATTRIBUTE_PRESSURE, p.data(), kept, &c0), "read pressures");
    double f[3] = {0.0, 0.0, 0.0};
    for (uint32_t i = 0; i < c0; ++i) {
      const sph::Vec3 at{static_cast<float>(x[3 * i] - kCentre[0]),
                         static_cast<float>(x[3 * i + 1] - kCentre[1]),
                         static_cast<float>(x[3 * i + 2] - kCentre[2])};
      const sph::LocalBoundaryShare s = sph::local_boundary_share(grid, map.data(), 1.0f, level, h, at);
      const double c = static_cast<double>(w.mass) * p[i] / (static_cast<double>(rho[i]) * rho[i]) * K;
      f[0] += c * s.gradient.x, f[1] += c * s.gradient.y, f[2] += c * s.gradient.z;
    }
    sph_collider_loads l;
    check(sph_collider_loads_init(&l), "sph_collider_loads_init");
    if (loads) {
      check(sph_collider_get_loads(w.world, box, &l), "sph_collider_get_loads");
      std::printf(
          "self-check, the first substep (no contacts): the walls' reaction on the host (%+.5f %+.5f %+.5f) "
          "N, the loads (%+.5f %+.5f %+.5f) N\n",
          f[0], f[1], f[2], static_cast<double>(l.force.x), static_cast<double>(l.force.y),
          static_cast<double>(l.force.z));
    }
    if (only) {
      // The bound: the sums' rounding (float per particle, in another order on the host), 1e-5 of
      // the force; on the CPU they agree bit for bit at the printed digits.
      const double got[3] = {l.force.x, l.force.y, l.force.z};
      double worst = 0.0, scale = 0.0;
      for (int k = 0; k < 3; ++k)
        worst = std::fmax(worst, std::fabs(f[k] - got[k])), scale += got[k] * got[k];
      const bool pass = loads && scale > 0.0 && worst <= 1e-5 * std::sqrt(scale);
      std::printf("self-check %s (largest difference %.3g N)\n", pass ? "passed" : "FAILED", worst);
      std::free(lattice);
      check(sph_sdf_destroy(tank_sdf), "sph_sdf_destroy");
      check(sph_sdf_destroy(box_sdf), "sph_sdf_destroy");
      check(support_world_close(&w), "support_world_close");
      return pass ? 0 : 1;
    }
  }
  // The tank's too (an inverted box, sign -1, its map at +delta), for the momentum balance below.
  sph::ShapeSpec tank_spec;
  tank_spec.kind = sph::ShapeKind::Box;
  tank_spec.half_extents = sph::Vec3{static_cast<float>(0.5 * kSide), 0.2f, static_cast<float>(0.5 * kSide)};
  tank_spec.voxel_size = static_cast<float>(0.5 * step);
  const auto tank_asset = sph::build_shape_sdf(tank_spec, 1u << 24);
  const float tank_level = static_cast<float>(calibration.offset);
  const auto tank_map = sph::compute_boundary_map(*tank_asset, h, tank_level, sph::CpuParallel(2));
  const sph::SdfGridView tank_grid = tank_asset->host_view();
  for (int frame = 0; frame < settle; ++frame) step_counted(0.02f);
  uint32_t count = 0;
  std::vector<float> velocity(x.size());
  check(support_read_by_id(w.world, SPH_ATTRIBUTE_VELOCITY, velocity.data(), kept, &count),
        "read velocities");
  for (uint32_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) momentum[k] -= static_cast<double>(w.mass) * velocity[3 * i + k];
  for (int frame = 0; frame < frames; ++frame) {
    const bool sampled = frame % every == 0;
    if (!reader.frame(w.world, sampled, frame, frame_time, step_counted)) return 1;
    if (!sampled) continue;
    count = reader.count;
    double sample_api[3] = {0.0, 0.0, 0.0}, sample_host[3] = {0.0, 0.0, 0.0}, sample_time = 0.0;
    bool sample_touched = false;  // a particle ended this substep on or in the box's surface
    if (loads) {
      sph_collider_loads l;
      check(sph_collider_loads_init(&l), "sph_collider_loads_init");
      check(sph_collider_get_loads(w.world, box, &l), "sph_collider_get_loads");
      sample_api[0] = l.force.x * l.frame_time, sample_api[1] = l.force.y * l.frame_time,
      sample_api[2] = l.force.z * l.frame_time;
      sample_time = l.frame_time;
      for (int k = 0; k < 3; ++k) api[k] += sample_api[k];
      api_time += l.frame_time;
      check(sph_collider_get_loads(w.world, tank, &l), "sph_collider_get_loads");
      tank_loads[0] += l.force.x * l.frame_time, tank_loads[1] += l.force.y * l.frame_time;
      tank_loads[2] += l.force.z * l.frame_time;
    }
    // The water level two ways: the hydrostatic level the interior's pressure gives (y + p / (rho0 g)
    // averaged over the particles more than h from every wall and 5 cm below the top plane), and the
    // top lattice plane's mean height over the tank's outer ring plus half a step (a plane stands for
    // half a step above it).
    double plane = 0.0, hydrostatic = 0.0, deep = 0.0;
    {
      std::vector<double> column(64, -1.0);  // 8 x 8 columns of 2 cm
      for (uint32_t i = 0; i < count; ++i) {
        const double px = x[3 * i], pz = x[3 * i + 2];
        const bool ring =
            std::fabs(px - kCentre[0]) > kHalf + 0.02 || std::fabs(pz - kCentre[2]) > kHalf + 0.02;
        if (!ring || px < h || pz < h || px > kSide - h || pz > kSide - h) continue;
        const int c = std::min(7, static_cast<int>(px / 0.02)) * 8 + std::min(7, static_cast<int>(pz / 0.02));
        column[c] = std::fmax(column[c], x[3 * i + 1]);
      }
      int used = 0;
      for (double c : column)
        if (c > 0.0) plane += c, ++used;
      plane = plane / used + 0.5 * step;
    }
    auto interior = [&](uint32_t i, double below) {
      const double px = x[3 * i], py = x[3 * i + 1], pz = x[3 * i + 2];
      const sph::Vec3 at{static_cast<float>(px - kCentre[0]), static_cast<float>(py - kCentre[1]),
                         static_cast<float>(pz - kCentre[2])};
      return sph::sample_distance(grid, at) > h && px > h && pz > h && px < kSide - h && pz < kSide - h &&
             py > h && py < below;
    };
    for (uint32_t i = 0; i < count; ++i)
      if (interior(i, plane - 0.05)) hydrostatic += x[3 * i + 1] + p[i] / (rho0 * kGravity), deep += 1.0;
    const double top = hydrostatic / deep;
    level_sum += top, plane_sum += plane;
    for (uint32_t i = 0; i < count; ++i) {
      const double local[3] = {x[3 * i] - kCentre[0], x[3 * i + 1] - kCentre[1], x[3 * i + 2] - kCentre[2]};
      const sph::Vec3 at{static_cast<float>(local[0]), static_cast<float>(local[1]),
                         static_cast<float>(local[2])};
      const double depth = top - x[3 * i + 1], ratio = p[i] / (rho0 * kGravity * depth);
      const sph::LocalBoundaryShare s = sph::local_boundary_share(grid, map.data(), 1.0f, level, h, at);
      const double distance = sph::sample_distance(grid, at);
      const double c = static_cast<double>(w.mass) * p[i] / (static_cast<double>(rho[i]) * rho[i]) * K;
      {
        const sph::Vec3 in_tank{static_cast<float>(x[3 * i] - 0.5 * kSide),
                                static_cast<float>(x[3 * i + 1] - 0.2),
                                static_cast<float>(x[3 * i + 2] - 0.5 * kSide)};
        const sph::Vec3 g =
            sph::local_boundary_share(tank_grid, tank_map.data(), -1.0f, tank_level, h, in_tank).gradient;
        tank_walls[0] += c * g.x, tank_walls[1] += c * g.y, tank_walls[2] += c * g.z;
      }
      Tally& t = tally[region_of(local)];
      const double f[3] = {c * s.gradient.x, c * s.gradient.y, c * s.gradient.z};
      for (int k = 0; k < 3; ++k) t.force[k] += f[k], sample_host[k] += f[k];
      if (region_of(local) == kSides) t.normal += std::fabs(std::fabs(local[0]) > kHalf ? f[0] : f[2]);
      t.count += f[0] != 0.0 || f[1] != 0.0 || f[2] != 0.0;
      {
        const sph::Vec3 end{static_cast<float>(after[3 * i] - kCentre[0]),
                            static_cast<float>(after[3 * i + 1] - kCentre[1]),
                            static_cast<float>(after[3 * i + 2] - kCentre[2])};
        const bool touched = sph::sample_distance(grid, end) < 1e-5f;
        t.contacts += touched;
        sample_touched = sample_touched || touched;
      }
      if (distance < h) t.near += 1.0, t.density += rho[i] / rho0, t.pressure_ratio += ratio;
      if (interior(i, plane - 0.03)) interior_ratio += ratio, interior_count += 1.0;
    }
    if (!sample_touched) {
      for (int k = 0; k < 3; ++k) clear_api[k] += sample_api[k], clear_host[k] += sample_host[k];
      clear_time += sample_time, ++clear_samples;
    }
    ++samples;
    reader.advance();
  }
  const double mean_level = level_sum / samples;
  const double top_face = kCentre[1] + kHalf, bottom_face = kCentre[1] - kHalf;
  std::printf(
      "submerged box, backend %s, solver %s, dt_max %g s, walls in the density: %u particles, h %.4f m, "
      "K %.1f kg/m^3, delta %.4f m; %d samples (substeps) over the last %.2f s\n",
      backend_name, dfsph ? "dfsph" : "wcsph", static_cast<double>(w.params.dt_max), kept,
      static_cast<double>(h), static_cast<double>(K), calibration.offset, samples,
      static_cast<double>(frame_time) * frames);
  std::printf(
      "water level %.4f m hydrostatic (top plane %.4f m, fill 0.2000): top face %.4f m deep, bottom face "
      "%.4f m; rho0 g V = %.4f N; "
      "interior (3 cm below the top plane and deeper) p / (rho0 g d) %.4f (%.0f particle samples)\n",
      mean_level, plane_sum / samples, mean_level - top_face, mean_level - bottom_face, expected,
      interior_count > 0.0 ? interior_ratio / interior_count : 0.0, interior_count);
  std::printf("%-15s %9s %9s %9s %8s %8s | %6s %8s %10s\n", "region", "Fy (N)", "Fy/rho0gV", "Fx,Fz (N)",
              "particles", "contacts", "near", "rho/rho0", "p/rho0gd");
  check(support_read_by_id(w.world, SPH_ATTRIBUTE_VELOCITY, velocity.data(), kept, &count),
        "read velocities");
  for (uint32_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) momentum[k] += static_cast<double>(w.mass) * velocity[3 * i + k];
  double total[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < kRegions; ++r) {
    const Tally& t = tally[r];
    const double fy = t.force[1] / samples;
    for (int k = 0; k < 3; ++k) total[k] += t.force[k] / samples;
    std::printf("%-15s %+9.4f %+9.4f %+4.3f,%+4.3f %8.1f %8.2f | %6.1f %8.4f %10.4f\n", kRegionNames[r], fy,
                fy / expected, t.force[0] / samples, t.force[2] / samples, t.count / samples,
                t.contacts / samples, t.near / samples, t.near > 0.0 ? t.density / t.near : 0.0,
                t.near > 0.0 ? t.pressure_ratio / t.near : 0.0);
  }
  const double top_all =
      (tally[kTop].force[1] + tally[kEdgeTop].force[1] + tally[kCornerTop].force[1]) / samples;
  const double bottom_all =
      (tally[kBottom].force[1] + tally[kEdgeBottom].force[1] + tally[kCornerBottom].force[1]) / samples;
  const double top_expected = -rho0 * kGravity * (mean_level - top_face) * area;
  const double bottom_expected = rho0 * kGravity * (mean_level - bottom_face) * area;
  const double side_expected = rho0 * kGravity * (mean_level - kCentre[1]) * area;
  std::printf(
      "faces against rho0 g d A at the face's depth: top face %+.4f N (%+.2f %%), with its edges and "
      "corners %+.4f N (%+.2f %%), expected %+.4f N; bottom face %+.4f N (%+.2f %%), with its edges and "
      "corners %+.4f N (%+.2f %%), expected %+.4f N; each side face's push %.4f N (%+.2f %%), expected "
      "%.4f N\n",
      tally[kTop].force[1] / samples, 100.0 * (tally[kTop].force[1] / samples / top_expected - 1.0), top_all,
      100.0 * (top_all / top_expected - 1.0), top_expected, tally[kBottom].force[1] / samples,
      100.0 * (tally[kBottom].force[1] / samples / bottom_expected - 1.0), bottom_all,
      100.0 * (bottom_all / bottom_expected - 1.0), bottom_expected, tally[kSides].normal / samples / 4.0,
      100.0 * (tally[kSides].normal / samples / 4.0 / side_expected - 1.0), side_expected);
  std::printf("walls' reaction, all regions: (%+.4f, %+.4f, %+.4f) N, buoyancy %+.2f %% of rho0 g V\n",
              total[0], total[1], total[2], 100.0 * (total[1] / expected - 1.0));
  if (top_face > plane_sum / samples) {
    // A box through the free surface (--centre-y): its force against rho0 g A (level - bottom) for
    // the hydrostatic level and for the top plane's.
    // The water's level by its volume at the last substep: each particle's m / max(rho, rho0) (the
    // compression counted, the free surface's summation deficit not), over the tank less the box.
    double volume = 0.0;
    for (uint32_t i = 0; i < count; ++i)
      volume +=
          static_cast<double>(w.mass) / std::fmax(static_cast<double>(rho[i]), static_cast<double>(rho0));
    const double by_volume = (volume - area * bottom_face) / (kSide * kSide - area);
    std::printf(
        "through the surface: the volume's level %.4f m, the hydrostatic level %.2f mm below it, the "
        "force's level (bottom + F / (rho0 g A)) %.2f mm below it\n",
        by_volume, 1e3 * (by_volume - mean_level),
        1e3 * (by_volume - bottom_face - total[1] / (rho0 * kGravity * area)));
    const double by_h = rho0 * kGravity * area * (mean_level - bottom_face),
                 by_plane = rho0 * kGravity * area * (plane_sum / samples - bottom_face);
    std::printf(
        "through the surface: rho0 g A (level - bottom) %.4f N by the hydrostatic level (force %+.2f %%), "
        "%.4f N "
        "by the top plane's (force %+.2f %%); the force's level less the plane's %.2f mm\n",
        by_h, 100.0 * (total[1] / by_h - 1.0), by_plane, 100.0 * (total[1] / by_plane - 1.0),
        1e3 * (total[1] / (rho0 * kGravity * area) + bottom_face - plane_sum / samples));
  }
  if (loads) {
    const double l[3] = {api[0] / api_time, api[1] / api_time, api[2] / api_time};
    std::printf(
        "the loads (SPH_FEATURE_COLLIDER_LOADS, the same substeps, contacts included): (%+.4f, %+.4f, %+.4f) "
        "N, buoyancy %+.2f %%\n",
        l[0], l[1], l[2], 100.0 * (l[1] / expected - 1.0));
    std::printf(
        "the contacts (the loads less the walls' reaction): (%+.4f, %+.4f, %+.4f) N, %+.2f %% of rho0 g V\n",
        l[0] - total[0], l[1] - total[1], l[2] - total[2], 100.0 * (l[1] - total[1]) / expected);
  }
  {
    // The fluid's momentum: dP/dt = M g - sum over colliders of their forces, so the forces that are
    // neither wall's reaction (both colliders' contacts; DFSPH's contact clamp too) are
    // M g - dP/dt - the walls' reactions. With the loads (WCSPH) the same from the loads, as a check.
    const double seconds = static_cast<double>(frame_time) * frames,
                 weight = kept * static_cast<double>(w.mass) * kGravity;
    double rest[3];
    for (int k = 0; k < 3; ++k)
      rest[k] = -(k == 1 ? weight : 0.0) - momentum[k] / seconds - total[k] - tank_walls[k] / samples;
    std::printf(
        "momentum balance: weight %.4f N, fluid dP/dt (%+.4f, %+.4f, %+.4f) N, tank walls' reaction (%+.4f, "
        "%+.4f, %+.4f) N; the colliders' other forces (contacts, DFSPH's clamp): (%+.4f, %+.4f, %+.4f) N\n",
        weight, momentum[0] / seconds, momentum[1] / seconds, momentum[2] / seconds, tank_walls[0] / samples,
        tank_walls[1] / samples, tank_walls[2] / samples, rest[0], rest[1], rest[2]);
    if (loads)
      std::printf("  the same from the loads, both colliders' contacts: (%+.4f, %+.4f, %+.4f) N\n",
                  (api[0] + tank_loads[0]) / api_time - total[0] - tank_walls[0] / samples,
                  (api[1] + tank_loads[1]) / api_time - total[1] - tank_walls[1] / samples,
                  (api[2] + tank_loads[2]) / api_time - total[2] - tank_walls[2] / samples);
    if (check_loads) {
      // The loads on the box against the host's sum of its walls' reaction, over the substeps that
      // end with no particle on the box's surface (a settled box still gets a touch now and then: a
      // float's rounding decides it, 0.0017-0.0022 N of contacts in 1 of 5 draws on either backend,
      // session 48), and the loads on both colliders against the fluid's momentum (M g - dP/dt)
      // over every substep, contacts included on both sides. Bound 1e-3 N (5e-4 of rho0 g V): the
      // float sums' rounding over ~2400 particles and the window (measured below 1e-5 N), and
      // DFSPH's contact clamp, which acts without a contact (0.0000 N once settled). At least half
      // the substeps must be free of contacts, or the box's comparison would rest on too few.
      double worst = 0.0;
      for (int k = 0; k < 3; ++k) {
        if (clear_samples > 0)
          worst = std::fmax(worst, std::fabs(clear_api[k] / clear_time - clear_host[k] / clear_samples));
        const double all = (api[k] + tank_loads[k]) / api_time;
        worst = std::fmax(worst, std::fabs(all - (-(k == 1 ? weight : 0.0) - momentum[k] / seconds)));
      }
      const bool enough = 2 * clear_samples >= samples;
      const bool pass = loads && enough && worst <= 1e-3;
      std::printf(
          "check-loads %s (largest difference %.3g N; the box's loads against its walls' reaction over %d "
          "of the %d substeps, those that end with no particle on its surface%s)\n",
          pass ? "passed" : "FAILED", worst, clear_samples, samples, enough ? "" : ": fewer than half");
      if (!pass) return 1;
    }
  }
  {
    // One line for scripts: the box's force (the loads where the world has them, else the walls'
    // reaction) and its parts against rho0 g V, the faces' own regions against rho0 g d A.
    const double walls = total[1] / expected - 1.0;
    const double force = loads ? api[1] / api_time / expected - 1.0 : walls;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::printf(
        "RESULT case=submerged_box backend=%s solver=%s step=%.5f h=%.5f particles=%u substeps=%llu "
        "seed=%lu samples=%d force_err=%+.2f walls_err=%+.2f top_err=%+.2f bottom_err=%+.2f side_err=%+.2f "
        "level=%.4f seconds=%.1f\n",
        backend_name, dfsph ? "dfsph" : "wcsph", step, static_cast<double>(h), kept,
        static_cast<unsigned long long>(substeps), perturb, samples, 100.0 * force, 100.0 * walls,
        100.0 * (tally[kTop].force[1] / samples / top_expected - 1.0),
        100.0 * (tally[kBottom].force[1] / samples / bottom_expected - 1.0),
        100.0 * (tally[kSides].normal / samples / 4.0 / side_expected - 1.0), mean_level, seconds);
  }
  std::free(lattice);
  check(sph_sdf_destroy(tank_sdf), "sph_sdf_destroy");
  check(sph_sdf_destroy(box_sdf), "sph_sdf_destroy");
  check(support_world_close(&w), "support_world_close");
  return 0;
}
