// A simulation world: its fixed configuration, runtime parameters, particle ids and time,
// its scene (colliders, sources, sinks, force fields), and the backend that holds and steps
// the particles.
#pragma once

#include <stdint.h>

#include <memory>
#include <vector>

#include "backend.h"
#include "config.h"
#include "frame_report.h"
#include "scene_objects.h"
#include "slot_map.h"

namespace sph {

enum ObjectTag : uint8_t { kTagCollider = 1, kTagSource = 2, kTagSink = 3, kTagForceField = 4 };

class World {
 public:
  World(const WorldConfig& config, std::unique_ptr<Backend> backend);

  const WorldConfig& config() const { return config_; }
  const RuntimeParams& params() const { return params_; }
  void set_params(const RuntimeParams& params) { params_ = params; }

  uint32_t particle_count() const { return backend_->particle_count(); }
  uint32_t free_capacity() const { return config_.capacity - particle_count(); }

  // Adds particles; throws Error(Capacity) if they do not fit. Returns the first new id.
  uint32_t spawn(const std::vector<Vec3>& positions, const std::vector<Vec3>* velocities);

  // Runs one frame: sources emit, then substeps with colliders, fields and sinks. Returns
  // false when max_substeps ran out before frame_dt. On an exception the world (particles,
  // ids, sources, collider poses) is as it was before the call.
  bool step(double frame_dt);

  const FrameReport& last_report() const { return report_; }
  double simulated_time() const { return simulated_time_; }
  float last_step_ms() const { return last_step_ms_; }
  const std::vector<Event>& events() const { return events_; }
  const std::vector<uint32_t>& removed_ids() const { return report_.removed_ids; }

  const Backend& backend() const { return *backend_; }
  Backend& backend() { return *backend_; }

  // The id the next particle gets.
  uint32_t next_id() const { return next_id_; }
  // Puts back the bookkeeping of a saved world (checkpoints); the caller has validated it.
  void restore_counters(uint32_t next_id, double simulated_time, const FrameReport& report,
                        float last_step_ms, const std::vector<Event>& events) {
    next_id_ = next_id;
    simulated_time_ = simulated_time;
    report_ = report;
    last_step_ms_ = last_step_ms;
    events_ = events;
  }

  SlotMap<Collider>& colliders() { return colliders_; }
  SlotMap<Source>& sources() { return sources_; }
  SlotMap<Sink>& sinks() { return sinks_; }
  SlotMap<ForceField>& force_fields() { return force_fields_; }
  const SlotMap<Collider>& colliders() const { return colliders_; }
  const SlotMap<Source>& sources() const { return sources_; }
  const SlotMap<Sink>& sinks() const { return sinks_; }
  const SlotMap<ForceField>& force_fields() const { return force_fields_; }

 private:
  void emit_sources(double frame_dt);
  SceneFrame build_scene_frame(double frame_dt) const;

  WorldConfig config_;
  RuntimeParams params_;
  std::unique_ptr<Backend> backend_;
  uint32_t next_id_ = 0;
  double simulated_time_ = 0.0;
  FrameReport report_;
  float last_step_ms_ = 0.0f;
  std::vector<Event> events_;
  SlotMap<Collider> colliders_{kTagCollider};
  SlotMap<Source> sources_{kTagSource};
  SlotMap<Sink> sinks_{kTagSink};
  SlotMap<ForceField> force_fields_{kTagForceField};
};

}  // namespace sph
