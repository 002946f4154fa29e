// SPDX-License-Identifier: MIT
// Sinks (thesis 4.4.2.3): the test that removes a particle, inside an SDF region or outside an
// axis-aligned box of the world.
#pragma once

#include <stdint.h>

#include "host_device.h"
#include "rigid_transform.h"
#include "sdf_sampling.h"
#include "vec3.h"

namespace sph {

enum class SinkMode : uint32_t { Region = 0, OutsideBounds = 1 };

struct SinkView {
  SinkMode mode;
  SdfGridView region;  // Region: remove where the distance is negative
  RigidTransform pose;
  Vec3 bounds_min;  // OutsideBounds: keep [min, max], world frame
  Vec3 bounds_max;
};

SPH_HD bool sink_removes(const SinkView& s, Vec3 x) {
  if (s.mode == SinkMode::OutsideBounds)
    return x.x < s.bounds_min.x || x.y < s.bounds_min.y || x.z < s.bounds_min.z || x.x > s.bounds_max.x ||
           x.y > s.bounds_max.y || x.z > s.bounds_max.z;
  return sample_distance(s.region, to_local(s.pose, x)) < 0.0f;
}

}  // namespace sph
