// SPDX-License-Identifier: MIT
// SceneRuntime: a SceneDesc built into a world through the public C API, and stepped frame by
// frame with its schedule (fluid bodies and sources that start later, sources and fields that
// stop, keyframed motion sent as target transforms).
#ifndef SPH_TOOLS_SCENE_RUNTIME_H
#define SPH_TOOLS_SCENE_RUNTIME_H

#include <cstdint>
#include <string>
#include <vector>

#include "scene_desc.h"
#include "sph_c.h"

namespace sph_tools {

// A message of one frame's events: `kind` says what it reports in the same words every frame it
// repeats in (sph-run folds the repeats by it: tools/run/message_fold.h), `text` the whole
// sentence; `count` the event's amount in `unit` (substeps, particles) where such amounts add up
// over frames, `unit` empty where they do not (a force, a pressure).
struct FrameMessage {
  std::string kind;
  std::string text;
  uint64_t count = 0;
  std::string unit;
};

class SceneRuntime {
 public:
  // How the runtime makes its world and adds a fluid body's particles. Without one, an undivided
  // world (sph_world_create) filled by the library's fills and spawn; sph-run-mpi passes a
  // distributed world's (tools/mpi/distributed_maker.h), whose fills are refused, so the
  // runtime then takes a fill's particles from a scratch world (lattice_fill.h) and adds them
  // through add_particles, on every rank at the same frame.
  class WorldMaker {
   public:
    virtual ~WorldMaker() = default;
    virtual sph_result create_world(sph_context* context, const sph_world_def* def, sph_world** out) = 0;
    // `count` particles, 3 floats each (velocities too).
    virtual sph_result add_particles(sph_world* world, const float* positions, const float* velocities,
                                     uint32_t count) = 0;
  };

  struct Collider {
    const ColliderDesc* desc;
    sph_sdf* sdf;  // owned by the runtime (one reference)
    sph_collider_id id;
  };

  // Creates a world on `context` (which must outlive the runtime) holding the scene's objects
  // and the fluid bodies of time 0. Throws SceneError (the object's path and the library's
  // message) when the library rejects a scene object, LibraryError for other failures.
  SceneRuntime(const SceneDesc& scene, sph_context* context, WorldMaker* maker = nullptr);
  ~SceneRuntime();
  SceneRuntime(const SceneRuntime&) = delete;
  SceneRuntime& operator=(const SceneRuntime&) = delete;

  sph_world* world() const { return world_; }
  const SceneDesc& scene() const { return scene_; }
  uint32_t frame() const { return frame_; }
  double time() const { return frame_ / static_cast<double>(scene_.fps); }
  const std::vector<Collider>& colliders() const { return colliders_; }
  // The probes, in the scene file's order (scene().probes).
  const std::vector<sph_probe_id>& probes() const { return probes_; }
  // The current pose of colliders()[i].
  sph_transform collider_pose(size_t i) const;

  // Steps one frame (1 / fps): first what is scheduled at its start, then sph_world_step.
  // Returns SPH_OK or SPH_INCOMPLETE (max_substeps ran out); throws SceneError or LibraryError.
  sph_result step_frame();

  // Warnings of the last step_frame (a source that reached the capacity, a DFSPH solve that
  // stopped at its cap), for the user.
  const std::vector<FrameMessage>& warnings() const { return warnings_; }
  // The last frame's threshold events (colliders' loads, probes' pressure).
  const std::vector<FrameMessage>& notices() const { return notices_; }

 private:
  void destroy_all();
  void apply_schedule(double t, double next_t);
  void add_fluid(const FluidDesc& fluid);
  void start_source(size_t i);
  void start_force_field(size_t i);
  void collect_events();
  // The most particles the world may hold, and what to raise for more (a growable world's
  // max_capacity, or a fixed world's capacity).
  uint32_t world_limit() const {
    return scene_.world.max_capacity > scene_.world.capacity ? scene_.world.max_capacity
                                                             : scene_.world.capacity;
  }
  const char* raise_hint() const {
    return scene_.world.max_capacity > scene_.world.capacity ? "raise world.max_capacity"
                                                             : "raise world.capacity";
  }

  const SceneDesc& scene_;
  sph_context* context_ = nullptr;
  WorldMaker* maker_ = nullptr;
  sph_world* world_ = nullptr;
  uint32_t frame_ = 0;
  std::vector<Collider> colliders_;
  std::vector<sph_probe_id> probes_;
  std::vector<bool> fluid_added_;
  struct Source {
    sph_sdf* sdf = nullptr;
    sph_source_id id{0};
    bool started = false, stopped = false;
  };
  std::vector<Source> sources_;
  std::vector<sph_sdf*> sink_sdfs_;
  struct ForceField {
    sph_sdf* region = nullptr;
    sph_force_field_id id{0};
    bool started = false, stopped = false;
  };
  std::vector<ForceField> fields_;
  std::vector<FrameMessage> warnings_;
  std::vector<FrameMessage> notices_;
};

}  // namespace sph_tools

#endif
