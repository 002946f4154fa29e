// SPDX-License-Identifier: MIT
// The small objects a world holds besides particles: colliders, sources, sinks and force
// fields, as the core keeps them between frames (made from specs by scene_build.h).
#pragma once

#include <stdint.h>

#include <memory>
#include <optional>
#include <vector>

#include "host_memory.h"
#include "position_reach.h"
#include "scene_specs.h"

namespace sph {

// A collider's loads over the last step: the time averages of the fluid's force and torque.
struct ColliderLoadResult {
  Vec3 force{0.0f, 0.0f, 0.0f};   // N, world frame
  Vec3 torque{0.0f, 0.0f, 0.0f};  // N m, about point
  Vec3 point{0.0f, 0.0f, 0.0f};   // the load point in the world at the end of the step
  double time = 0.0;              // the span of the average (the step's time advanced), s
};

struct Collider {
  std::shared_ptr<const SdfAsset> sdf;
  RigidTransform pose = identity_pose();  // where the collider is now (start of the next frame)
  std::optional<RigidTransform> target;   // where it must be at the end of the next frame
  ColliderMaterial material;
  bool inverted = false;
  Vec3 load_point{0.0f, 0.0f, 0.0f};  // collider frame: the torque of its loads is about it
  float load_threshold = 0.0f;        // N: a step whose mean force reaches it reports an event; 0 = none
  ColliderLoadResult loads;           // of the last step (SPH_FEATURE_COLLIDER_LOADS)
};

// The most a rate-limited source may owe (particles): a frame that stops early takes back the
// credit of the time it did not simulate, which its emission at the frame's start had spent.
constexpr double kMaxSourceDebt = 1e15;
// The most a rate budget read from a checkpoint may hold: a budget grows by at most rate x frame
// time a step and is capped at one region's lattice (World::step), far below this.
constexpr double kMaxSourceCredit = 1e15;

struct Source {
  std::shared_ptr<const SdfAsset> region;
  RigidTransform pose = identity_pose();
  SourceMode mode = SourceMode::FillOnce;
  float spacing = 0.0f;
  float min_distance = 0.0f;
  Vec3 velocity{0.0f, 0.0f, 0.0f};
  bool velocity_from_field = false;
  float rate = 0.0f;            // Continuous: particles per second at most; 0 = no limit
  double rate_budget = 0.0;     // fractional particles carried between frames; negative: a debt
                                // (World::step), at least -kMaxSourceDebt
  bool done = false;            // FillOnce: already emitted
  HostVector<Vec3> lattice;     // FCC points inside the region, in the region's frame
  LatticeBox lattice_bounds;    // lattice_box(lattice), set wherever the lattice is
  uint32_t user_attribute = 0;  // its particles' (SPH_FEATURE_USER_ATTRIBUTE)
};

struct Sink {
  SinkMode mode = SinkMode::Region;
  std::shared_ptr<const SdfAsset> region;
  RigidTransform pose = identity_pose();
  Vec3 bounds_min{0.0f, 0.0f, 0.0f};
  Vec3 bounds_max{0.0f, 0.0f, 0.0f};
};

struct ForceField {
  ForceFieldKind kind = ForceFieldKind::Uniform;
  std::shared_ptr<const SdfAsset> region;
  std::shared_ptr<const SdfAsset> grid;
  RigidTransform pose = identity_pose();
  Vec3 vector{0.0f, 0.0f, 0.0f};
  float strength = 0.0f;
  float falloff_radius = 0.0f;
};

// A probe or gauge (physics/probe_sampling.h) and its reading of the last step.
struct ProbeReading {
  uint32_t samples = 0;
  float density = 0.0f, pressure = 0.0f, pressure_max = 0.0f, kernel_sum = 0.0f, water_height = 0.0f;
  Vec3 velocity{0.0f, 0.0f, 0.0f};
  double time = 0.0;
};

struct Probe {
  bool gauge = false;
  bool every_substep = false;
  Vec3 position{0.0f, 0.0f, 0.0f};
  Vec3 direction{0.0f, 0.0f, 0.0f};  // gauges: unit, or zero for "against gravity"
  float length = 0.0f;               // gauges
  uint32_t sample_count = 1;         // gauges: the column integral's steps
  float pressure_threshold = 0.0f;   // Pa: a step whose peak pressure reaches it reports an event; 0 = none
  ProbeReading reading;

  // The points it samples a step: one for a point probe, its samples for a gauge.
  uint32_t points() const { return gauge ? sample_count : 1u; }
};

// Values equal to sph_event_type. The solver's events name no object (object_id 0).
enum class EventType : uint32_t {
  SourceCapacityReached = 1,
  SinkRemoved = 2,
  PressureSolveCapped = 3,
  DivergenceSolveCapped = 4,
  CapacityGrown = 5,          // object: the source whose emission grew the world; count: the new capacity
  ColliderLoadExceeded = 6,   // object: the collider; count: its mean force's magnitude, N
  ProbePressureExceeded = 7,  // object: the probe; count: its reading's peak pressure, Pa
};

struct Event {
  EventType type;
  uint64_t object_id;
  uint32_t count;
};

// FCC lattice points at `spacing` inside an asset's negative region, in the asset's frame.
// Throws Error(Capacity) when the region's box holds more than max_points lattice points.
HostVector<Vec3> lattice_inside(const SdfAsset& region, float spacing, uint64_t max_points);

}  // namespace sph
