// SPDX-License-Identifier: MIT
// libFuzzer harness: the input is the text of a scene file (tools/scene, read by sph-run). The
// parser must either return a scene or throw SceneError (a path and a message); anything else
// (another exception, a crash, undefined behaviour) is a bug. A scene that parses is then
// built into a world on a CPU context and stepped one frame, with its size bounded so an input
// stays fast: at most 2048 particles, 4 substeps, small SDF grids and source lattices (scenes
// beyond that are legal, just too slow to build here). Building may throw SceneError or
// LibraryError; afterwards no library object may be left alive but the context.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "library_error.h"
#include "scene_error.h"
#include "scene_parser.h"
#include "scene_runtime.h"
#include "shape_grid_estimate.h"
#include "sph_c.h"

using sph_fuzz::create_cpu_context;
using sph_fuzz::violation;

namespace {

constexpr uint32_t kMaxCapacity = 2048;
constexpr uint32_t kMaxSubsteps = 4;
constexpr double kMaxVoxels = 1 << 16;
constexpr double kMaxLattice = 1 << 16;

// Voxels and box volume of a shape's grid; .vdb shapes count as small (the base folder holds no
// files, so they fail).
double shape_voxels(const sph_tools::ShapeDesc& s, double* volume) {
  *volume = 0.0;
  if (s.kind != sph_tools::ShapeDesc::Kind::kAnalytic) return 0.0;
  const double voxels = sph_fuzz::shape_grid_voxels(s.analytic),
               v = sph_fuzz::shape_size_or_default(s.analytic.voxel_size, 0.01);
  *volume = voxels * v * v * v;
  return voxels;
}

// Whether building and stepping the scene stays within the harness's budget (the library
// refuses grids over 2^31 voxels itself, so those pass).
bool small_enough(const sph_tools::SceneDesc& scene) {
  auto ok_shape = [](const sph_tools::ShapeDesc& s, double spacing) {
    double volume;
    const double voxels = shape_voxels(s, &volume);
    if (!std::isfinite(voxels) || voxels > 8.0 * 2147483648.0) return true;
    if (voxels > kMaxVoxels) return false;
    const double lattice = volume * std::sqrt(2.0) / (spacing * spacing * spacing);
    return spacing <= 0.0 || !std::isfinite(lattice) || lattice <= kMaxLattice;
  };
  const double world_spacing = scene.world.particle_spacing;
  for (const auto& c : scene.colliders)
    if (!ok_shape(c.shape, world_spacing)) return false;
  for (const auto& s : scene.sources)
    if (!ok_shape(s.shape, s.spacing > 0.0f ? s.spacing : world_spacing)) return false;
  for (const auto& s : scene.sinks)
    if (!ok_shape(s.shape, world_spacing)) return false;
  for (const auto& f : scene.force_fields)
    if (f.has_region && !ok_shape(f.region, world_spacing)) return false;
  return true;
}

uint32_t live_objects() {
  uint32_t n = 0;
  FUZZ_CALL(sph_get_live_object_count(&n));
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  sph_tools::SceneDesc scene;
  try {
    scene = sph_tools::parse_scene(text, "/nonexistent-sph-fuzz-dir");
  } catch (const sph_tools::SceneError& e) {
    if (std::string(e.what()).empty()) violation("a SceneError without a message");
    return 0;
  }
  scene.world.capacity = std::min(scene.world.capacity, kMaxCapacity);
  scene.params.max_substeps = std::min(scene.params.max_substeps, kMaxSubsteps);
  if (!small_enough(scene)) return 0;

  sph_context* context = create_cpu_context();
  const uint32_t baseline = live_objects();
  try {
    sph_tools::SceneRuntime runtime(scene, context);
    runtime.step_frame();
  } catch (const sph_tools::SceneError&) {
  } catch (const sph_tools::LibraryError& e) {
    // A step that failed for the scene's numbers (NaN, capacity) is the library's to report.
    if (e.code() == SPH_ERROR_INTERNAL) violation("the library failed internally: %s", e.what());
  }
  if (live_objects() != baseline) violation("the scene runtime leaked %u objects", live_objects() - baseline);
  if (FUZZ_CALL(sph_context_destroy(context)) != SPH_OK) violation("the context is still busy");
  return 0;
}
