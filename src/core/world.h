// SPDX-License-Identifier: MIT
// A simulation world: its fixed configuration, runtime parameters, particle ids and time,
// its scene (colliders, sources, sinks, force fields), and the backend that holds and steps
// the particles.
#pragma once

#include <stdint.h>

#include <memory>
#include <string>
#include <vector>

#include "backend.h"
#include "config.h"
#include "frame_report.h"
#include "host_memory.h"
#include "scene_objects.h"
#include "scene_specs.h"
#include "slot_map.h"

namespace sph {

enum ObjectTag : uint8_t {
  kTagCollider = 1,
  kTagSource = 2,
  kTagSink = 3,
  kTagForceField = 4,
  kTagProbe = 5
};

// A world's whole scene as slot tables (checkpoints): objects made by scene_build.h's make_*,
// slot layouts the caller has validated (generations in [1, 2^24), the free list naming every
// empty slot once), so that a restored world issues and accepts the same ids.
struct SceneTables {
  SlotTable<Collider> colliders;
  SlotTable<Source> sources;
  SlotTable<Sink> sinks;
  SlotTable<ForceField> force_fields;
};

class World {
 public:
  World(const WorldConfig& config, std::unique_ptr<Backend> backend);

  const WorldConfig& config() const { return config_; }
  const RuntimeParams& params() const { return params_; }
  void set_params(const RuntimeParams& params) { params_ = params; }

  uint32_t particle_count() const { return backend_->particle_count(); }
  // Particles that may still be added: up to max_capacity (the world grows on demand).
  uint32_t room() const { return config_.max_capacity - particle_count(); }
  // Times reserve_particles reallocated the backend since the world was made (or loaded).
  uint32_t capacity_growths() const { return capacity_growths_; }

  // Makes the backend hold room for `total` particles: nothing when it has; otherwise grows
  // it to max(total, 2 x capacity), clamped to max_capacity (geometric, so n single spawns
  // cost O(log n) reallocations). Error(Capacity) naming max_capacity when total exceeds it;
  // the backend's OutOf*Memory when it cannot allocate. Either way the world is as it was.
  // Returns whether it grew.
  bool reserve_particles(uint64_t total);
  // "the world's max_capacity N", for the messages of every refusal past it.
  std::string capacity_limit() const;

  // ---- particles in (world_particles.cpp) ----
  // The entry points validate everything before they change anything: on any error the world
  // is as it was. Field errors are FieldErrors named as the public descs name them
  // ("positions[3]", "max"); the C layer puts "desc->" in front.
  //
  // FieldError(Capacity) "count" unless `count` more particles fit under max_capacity
  // (callers check before they copy a large input).
  void require_room_for_particles(uint64_t count) const;
  // Adds particles at finite positions within 65536 particle spacings of the origin, with
  // finite velocities (or none: at rest). Returns the first new id; ids are consecutive.
  uint32_t add_particles(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities);
  // A distributed world's collective add (src/mpi): this rank's particles, validated as
  // add_particles does, take ids first_id, first_id + 1, ...; the world's next id is then
  // next_id_after (the same on every rank). On error the world is as it was.
  uint32_t add_rank_particles(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities,
                              uint32_t first_id, uint32_t next_id_after);
  // Undoes the last add_rank_particles (another rank refused its particles).
  void undo_rank_particles(uint32_t count_before, uint32_t next_id_before);
  // FCC lattices at the world's spacing in a box or a sphere (fcc_lattice.h); an empty box or
  // radius 0 fills nothing. Error(Capacity) when the lattice does not fit under max_capacity.
  // Returns the count.
  uint32_t fill_box(const FillBoxSpec& spec);
  uint32_t fill_sphere(const FillSphereSpec& spec);

  // ---- particles written (world_particle_writes.cpp) ----
  // Each checks everything first and changes nothing on error. Particles are addressed as
  // Backend::copy_attribute reads them: [first, first + n) in the current storage order,
  // InvalidArgument "first/count" when the range passes the particle count. Value errors are
  // FieldErrors naming "src[i]" (the i-th value given) or "ids[k]".
  //
  // Positions (finite, within 65536 spacings of the origin or the particle's own) or velocities (finite,
  // speed below 1.8e19 m/s) of particles [first, first + values.size()); kind is Position or Velocity.
  // Error(InvalidArgument) "first/count" unless [first, first + count) lies in the particles.
  void require_particle_range(uint32_t first, uint64_t count) const;
  void set_vectors(AttributeKind kind, uint32_t first, const HostVector<Vec3>& values);
  // The user attribute of particles [first, first + values.size()); Error(FeatureDisabled)
  // without kFeatureUserAttribute.
  void set_user_attributes(uint32_t first, const HostVector<uint32_t>& values);
  // Removes the particles with these ids (each a live particle's, none twice); the rest keep
  // their order. The ids join removed_ids() (cleared by the next step).
  void remove_particles(const HostVector<uint32_t>& ids);

  // Runs one frame: sources emit, then substeps with colliders, fields and sinks. Returns
  // false when max_substeps ran out before frame_dt, or `interrupt` stopped it at a substep
  // boundary (raised before the step starts: nothing changes but the report, which says no
  // substep ran). On an exception the world (particles, ids, sources, collider poses) is as it
  // was before the call.
  // `enqueued`, when set, is called once the frame's device work is enqueued (frame_enqueued.h).
  bool step(double frame_dt, const StepInterrupt& interrupt = StepInterrupt{},
            const FrameEnqueuedHook& enqueued = FrameEnqueuedHook{});

  // Builds what the next step would build before its first substep (the collider assets' device
  // copies, their boundary-density maps, the scene's buffers: Backend::prepare_scene), so that a
  // caller pays for it when it chooses. Changes nothing a step or a checkpoint sees.
  void prepare();

  const FrameReport& last_report() const { return report_; }
  double simulated_time() const { return simulated_time_; }
  float last_step_ms() const { return last_step_ms_; }
  const HostVector<Event>& events() const { return events_; }
  const HostVector<uint32_t>& removed_ids() const { return report_.removed_ids; }

  const Backend& backend() const { return *backend_; }
  Backend& backend() { return *backend_; }

  // The id the next particle gets.
  uint32_t next_id() const { return next_id_; }
  // Puts back the bookkeeping of a saved world (checkpoints); the caller has validated it.
  void restore_counters(uint32_t next_id, double simulated_time, const FrameReport& report,
                        float last_step_ms, const HostVector<Event>& events) {
    next_id_ = next_id;
    simulated_time_ = simulated_time;
    report_ = report;
    last_step_ms_ = last_step_ms;
    events_ = events;
  }

  // ---- scene objects (world_scene.cpp) ----
  // add_* validates its spec (scene_build.h), throws a FieldError naming the field, or
  // Error(Capacity) past 65536 objects of a kind (or a source region of more than 2^28
  // lattice points), and leaves the world unchanged on error. Returns the new generational id
  // (slot_map.h); ids are never 0.
  uint64_t add_collider(const ColliderSpec& spec);
  uint64_t add_source(const SourceSpec& spec);
  uint64_t add_sink(const SinkSpec& spec);
  uint64_t add_force_field(const ForceFieldSpec& spec);
  // Removes an object. Id 0 is a no-op; a stale id or one of another kind or world is
  // Error(InvalidHandle).
  void remove_collider(uint64_t id);
  void remove_source(uint64_t id);
  void remove_sink(uint64_t id);
  void remove_force_field(uint64_t id);
  // Setters: Error(InvalidHandle) "id: ..." for an id that names no live object of the kind,
  // FieldError for a bad value (a pose must pass require_pose, pose_rules.h).
  void set_collider_target(uint64_t id, const RigidTransform& target);
  void teleport_collider(uint64_t id, const RigidTransform& pose);
  void set_collider_material(uint64_t id, const ColliderMaterial& material);
  // The point (collider frame) its loads' torque is taken about; InvalidArgument if not finite.
  void set_collider_load_point(uint64_t id, Vec3 point);
  // The force (N) whose reaching makes a step report ColliderLoadExceeded; 0 = none;
  // InvalidArgument if negative or not finite.
  void set_collider_load_threshold(uint64_t id, float threshold);
  void set_source_pose(uint64_t id, const RigidTransform& pose);
  void set_force_field_pose(uint64_t id, const RigidTransform& pose);
  // A live collider; Error(InvalidHandle) otherwise.
  const Collider& collider(uint64_t id) const;
  // ---- probes and gauges (world_probes.cpp; physics/probe_sampling.h) ----
  // add_probe: FieldError naming the field for a bad spec, Error(Capacity) past 65536 probes or
  // kMaxProbePoints sample points in all; the world is unchanged on error. Probes are not part of
  // SceneTables: a checkpoint of format 6 (kFirstProbeVersion) or later carries them (restore_probes), an
  // older one has none and sph_world_restore keeps the world's own (adopt_probes).
  uint64_t add_probe(const ProbeSpec& spec);
  void remove_probe(uint64_t id);
  // The peak pressure (Pa) whose reaching makes a step report ProbePressureExceeded; 0 = none;
  // InvalidArgument if negative or not finite.
  void set_probe_pressure_threshold(uint64_t id, float threshold);
  // A live probe; Error(InvalidHandle) otherwise.
  const Probe& probe(uint64_t id) const;
  const SlotMap<Probe>& probes() const { return probes_; }
  // The sample points of all probes a step (a point probe one, a gauge its samples).
  uint64_t probe_points() const { return probe_points_; }
  // Takes over another world's probes with their ids, readings cleared (a restore from a file
  // before format 6 keeps the world's probes). Their ids keep `from`'s world tag, which may then
  // differ from this world's (tag 0, the old file's): a later save writes this world's tag, so
  // those probes' ids change in a world loaded from it.
  void adopt_probes(const World& from);
  // A checkpoint's probes (checkpoint_reader.cpp), readings cleared.
  void restore_probes(SlotTable<Probe> table);

  // Replaces the whole scene (checkpoints; see SceneTables).
  void restore_scene(SceneTables tables);

  // The world tag in the ids of its objects (slot_map.h): the C layer gives a new world its
  // context's next tag, a loaded world the saved world's (0 from a file before format 15), so
  // that another world's ids are refused and a loaded world's are the saved ones.
  uint16_t id_tag() const { return colliders_.world_tag(); }
  void set_id_tag(uint16_t tag);
  // Takes over `before`'s highest issued generations (a restore replaces a world by a world
  // loaded beside it: no id `before` issued is issued again).
  void keep_issued_ids(const World& before);
  // Where an object of `before` with the same id uses an asset holding the same bits as this
  // world's copy (a restore of a checkpoint whose assets the caller has not changed since), this
  // world's object takes `before`'s asset instead of its copy: it follows the caller's
  // sph_sdf_update again, and its boundary maps are found (Backend::adopt_asset_caches). An object
  // with no namesake in `before` (an undone deletion) takes any asset of `before`'s objects with
  // the same bits.
  void keep_caller_assets(const World& before);

  // Read-only views; everything that changes the scene goes through the entry points above.
  const SlotMap<Collider>& colliders() const { return colliders_; }
  const SlotMap<Source>& sources() const { return sources_; }
  const SlotMap<Sink>& sinks() const { return sinks_; }
  const SlotMap<ForceField>& force_fields() const { return force_fields_; }

 private:
  // Adds particles without the entry point's checks (sources emit inside their region), with
  // user_attribute as their user attribute where the world carries one.
  uint32_t spawn(const HostVector<Vec3>& positions, const HostVector<Vec3>* velocities,
                 uint32_t user_attribute = 0);
  // Why a position is refused (world_particles.cpp), or empty when it is fine: not finite, or
  // (check_reach) beyond the positions' reach (position_reach.h).
  std::string position_problem(const Vec3& p, bool check_reach = true) const;
  // The end of fill_box and fill_sphere: checks the points (errors name region_fields) and
  // adds them at one velocity.
  uint32_t fill(const HostVector<Vec3>& points, const Vec3& velocity, const char* region_fields);
  void emit_sources(double frame_dt);
  // A distributed world's emission (world_rank_sources.cpp), the same decision on every rank:
  // keep[i] stays set where no rank's particle is too close; which points lie in this rank's
  // slab; how many accepted points fit on every rank; then this rank's points appended with the
  // world's ids (next_id_ grows by all of them) and added to `existing`.
  void agree_clear_points(HostVector<char>& keep) const;
  HostVector<char> points_of_this_rank(const HostVector<Vec3>& points) const;
  size_t rank_emission_fits(const HostVector<char>& mine, size_t allowed) const;
  void emit_on_ranks(const HostVector<Vec3>& points, const HostVector<Vec3>& velocities,
                     const HostVector<char>& mine, uint32_t user_attribute, HostVector<Vec3>& existing);
  SceneFrame build_scene_frame(double frame_dt) const;
  void add_probe_frames(SceneFrame& scene) const;
  void store_probe_readings(const FrameReport& report);

  WorldConfig config_;
  RuntimeParams params_;
  std::unique_ptr<Backend> backend_;
  uint32_t next_id_ = 0;
  double simulated_time_ = 0.0;
  FrameReport report_;
  float last_step_ms_ = 0.0f;
  uint32_t capacity_growths_ = 0;
  bool rank_add_ = false;  // inside add_rank_particles (a distributed world's only spawn)
  HostVector<Event> events_;
  SlotMap<Collider> colliders_{kTagCollider};
  SlotMap<Source> sources_{kTagSource};
  SlotMap<Sink> sinks_{kTagSink};
  SlotMap<ForceField> force_fields_{kTagForceField};
  SlotMap<Probe> probes_{kTagProbe};
  uint64_t probe_points_ = 0;  // probe_points(): kept with every change of probes_
};

}  // namespace sph
