// SPDX-License-Identifier: MIT
// What a backend needs to know about a world's scene for one frame: colliders with their
// start and end poses, force fields and sinks. Assets are held by reference; each backend
// turns them into grid views over its own memory.
#pragma once

#include <stdint.h>

#include <memory>
#include <vector>

#include "../physics/collider_response.h"
#include "../physics/force_fields.h"
#include "../physics/probe_sampling.h"
#include "../physics/sink_region.h"
#include "frame_enqueued.h"
#include "host_memory.h"
#include "sdf_asset.h"
#include "step_interrupt.h"

namespace sph {

struct ColliderFrame {
  std::shared_ptr<const SdfAsset> sdf;
  ColliderView view;  // everything but view.sdf, which the backend fills
};

struct ForceFieldFrame {
  std::shared_ptr<const SdfAsset> region;  // may be null: the field acts everywhere
  std::shared_ptr<const SdfAsset> grid;    // grid fields: accelerations in the velocity channel
  ForceFieldView view;                     // everything but the grid views
};

struct SinkFrame {
  uint64_t id;
  std::shared_ptr<const SdfAsset> region;  // null for OutsideBounds
  SinkView view;                           // everything but view.region
};

struct SceneFrame {
  HostVector<ColliderFrame> colliders;
  HostVector<ForceFieldFrame> fields;
  HostVector<SinkFrame> sinks;
  // Probes and gauges (probe_sampling.h), sampled at each substep's density pass; their sample
  // points number probe_points (a probe's are [first_point, first_point + point_count)).
  HostVector<ProbeView> probes;
  uint32_t probe_points = 0;
  float max_collider_speed = 0.0f;  // fastest collider surface point, m/s (for the step size)
  StepInterrupt interrupt;          // checked between substeps (CUDA: on its stream driver only)
  FrameEnqueuedHook enqueued;       // optional (frame_enqueued.h)

  bool empty() const { return colliders.empty() && fields.empty() && sinks.empty(); }
};

// Fills the grid views of a scene from a function mapping an asset to its view (host memory
// on the CPU, device memory on CUDA).
template <class ViewOf>
void bind_scene_views(SceneFrame& scene, ViewOf&& view_of) {
  for (ColliderFrame& c : scene.colliders) c.view.sdf = view_of(*c.sdf);
  for (ForceFieldFrame& f : scene.fields) {
    if (f.region) f.view.region = view_of(*f.region);
    if (f.grid) f.view.grid = view_of(*f.grid);
  }
  for (SinkFrame& s : scene.sinks)
    if (s.region) s.view.region = view_of(*s.region);
}

}  // namespace sph
