// What a backend reports about one frame (one sph_world_step).
#pragma once

#include <stdint.h>

#include <vector>

namespace sph {

enum StageIndex : int {
  kStageHashSort = 0,
  kStageCellRanges = 1,
  kStageDensity = 2,
  kStageForces = 3,
  kStageIntegrate = 4,
  kStageCollide = 5,
  kStageEmit = 6,
  kStageOther = 7,
  kStageCount = 8,
};

// One collider's impulses over a frame (SPH_FEATURE_COLLIDER_LOADS, physics/collider_loads.h),
// summed in double in a fixed order.
struct ColliderLoadSums {
  double linear[3] = {0.0, 0.0, 0.0};   // N s, world frame
  double angular[3] = {0.0, 0.0, 0.0};  // N m s, about the load point
};

struct FrameReport {
  uint32_t substeps = 0;
  bool completed = true;       // false when max_substeps ran out before the frame's end
  double time_advanced = 0.0;  // seconds
  float dt_min = 0.0f;
  float dt_max = 0.0f;
  float max_speed = 0.0f;
  float density_min = 0.0f;
  float density_mean = 0.0f;
  float density_max = 0.0f;
  float neighbors_mean = 0.0f;
  uint32_t neighbors_max = 0;
  float stage_ms[kStageCount] = {};
  std::vector<uint32_t> removed_ids;             // ids sinks removed during the frame
  std::vector<uint32_t> removed_by_sink;         // count per sink, in SceneFrame::sinks order
  std::vector<ColliderLoadSums> collider_loads;  // per collider in SceneFrame::colliders order (loads on)
};

}  // namespace sph
