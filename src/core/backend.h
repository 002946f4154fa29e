// SPDX-License-Identifier: MIT
// The interface the core drives a backend through. A backend owns the particle state (in host
// or device memory) and runs whole frames; the core validates input, assigns ids and keeps
// parameters. The core never names a backend: src/factory makes them.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <vector>

#include "../physics/float4_types.h"
#include "../physics/vec3.h"
#include "config.h"
#include "distributed.h"
#include "frame_report.h"
#include "particle_snapshot.h"
#include "rank_transport.h"
#include "scene_frame.h"
#include "status.h"

namespace sph {

enum class AttributeKind : uint32_t {
  Position = 0,
  Velocity = 1,
  Density = 2,
  Pressure = 3,
  Id = 4,
  User = 5
};

// A device-resident attribute: element k of particle i is at address + i * stride.
struct DeviceAttributeView {
  uint64_t address = 0;
  uint64_t stride = 0;        // bytes between particles
  uint32_t element_size = 0;  // 12 (3 x float32) or 4
  uint32_t count = 0;         // particles
  uint64_t epoch = 0;         // data_epoch() when the view was taken
  int device = 0;
};

class Backend {
 public:
  virtual ~Backend() = default;

  virtual uint32_t particle_count() const = 0;

  // Appends n particles (velocities may be null = zero) with ids first_id, first_id + 1, ...,
  // and user_attribute as their user attribute (when the world carries one; else ignored).
  // The caller has checked capacity and finiteness. All-or-nothing: throws on failure and
  // leaves the particles as they were.
  virtual void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id,
                      uint32_t user_attribute) = 0;

  // What the next frames need beside the particle storage, so that a growth reserves their
  // capacity-sized buffers too (a frame that grows its world can then fail only before the
  // growth or after every buffer it needs exists: never with a grown world and a step rolled
  // back).
  struct GrowthNeeds {
    bool sinks = false;           // the world has sinks (the sink compaction's buffers)
    uint32_t load_colliders = 0;  // colliders whose loads a frame sums (their block sums)
  };
  // Makes room for `capacity` particles (more than config.capacity; the caller has checked
  // it against max_capacity): every per-particle buffer is reallocated and the particles are
  // kept. All-or-nothing: throws Error(OutOfHostMemory / OutOfDeviceMemory) and leaves the
  // backend as it was. Device pointers taken before (device_attribute) are stale after.
  virtual void reserve(uint32_t capacity, const GrowthNeeds& needs) = 0;

  // Makes the device copies a frame of `scene` needs (collider SDFs, boundary maps, scene and
  // probe buffers) ahead of the frame. The world calls it before a step's sources may grow the
  // storage, so that the step cannot fail on one of these allocations with the world already
  // grown (a grown world and a rolled-back step would differ from the world before the call).
  // Throws like step_scene_frame; a backend without such copies does nothing.
  virtual void prepare_scene(const SceneFrame& /*scene*/, const RuntimeParams& /*params*/) {}

  // Runs adaptive substeps until frame_dt is reached or params.max_substeps is spent, with the
  // scene's colliders, force fields and sinks. On a non-finite state it restores the particles
  // as they were before the call and throws Error(Status::NonFinite).
  virtual FrameReport step_scene_frame(double frame_dt, const RuntimeParams& params,
                                       const SceneFrame& scene) = 0;

  // The step controller's carried inputs (the max speed and max acceleration the next step is
  // chosen from). A step that emitted particles and then failed truncates them, and truncate()
  // recomputes the max speed from the velocities left, which need not equal what the world
  // carried (collisions and sinks change velocities after the max is taken): World::step saves
  // these before its emission and restores them after the truncation, so a failed step changes
  // no carried field.
  virtual void save_step_inputs() = 0;
  virtual void restore_step_inputs() = 0;

  // Drops the particles from index `count` on (used to undo an emission when a step fails;
  // emitted particles are appended, so they are the last ones).
  virtual void truncate(uint32_t count) = 0;

  // Writes particles [first, first + count) of one attribute to dst with a byte stride, as
  // float32 x3 (position, velocity), float32 (density, pressure) or uint32 (id, user; the caller
  // has checked that the world carries a user attribute).
  virtual void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                              size_t stride) const = 0;

  // The whole particle state (see ParticleSnapshot). Blocks until the data is on the host.
  virtual ParticleSnapshot export_particles() const = 0;
  // Replaces the whole particle state. The caller has checked count <= capacity, that the
  // arrays have equal lengths and that the values are finite. Throws on failure.
  virtual void import_particles(const ParticleSnapshot& snapshot) = 0;

  // Bytes held for particles and grids (device bytes on a GPU backend).
  virtual uint64_t memory_bytes() const = 0;

  // ---- distributed worlds (include/sph_mpi.h): one backend per rank ---------------------------
  // Makes this backend one rank of a world spread over `ranks` (before it holds particles):
  // every frame becomes collective (all ranks step together), particles migrate to the rank
  // whose slab holds them, halos are exchanged before each neighbour pass. Error(Unsupported)
  // naming the feature when the world uses one that does not work distributed yet (or this
  // backend has no distributed path).
  virtual void attach_ranks(std::shared_ptr<const RankTransport> /*ranks*/, const DistributedOptions&) {
    throw Error(Status::Unsupported, "world: this backend has no distributed path (sph_mpi.h)");
  }
  // The ranks attach_ranks gave (null: not a distributed world).
  virtual const RankTransport* rank_transport() const { return nullptr; }
  // A CPU rank's hash+sort stage in its parts (null elsewhere).
  virtual const HaloPhaseTimes* halo_phase_times() const { return nullptr; }
  bool distributed() const { return rank_transport() != nullptr; }
  virtual DistributedCounters distributed_counters() const { return DistributedCounters{}; }
  // The ranks as attach_ranks took them (a restore attaches them to the state it builds).
  virtual std::shared_ptr<const RankTransport> shared_rank_transport() const { return nullptr; }
  // A distributed world's decomposition and counters (a rank's checkpoint); the restore takes a
  // state whose cuts are valid for the ranks (SlabDecomposition::valid).
  virtual DistributedState distributed_state() const { return DistributedState{}; }
  virtual void restore_distributed_state(const DistributedState&) {
    throw Error(Status::Internal, "restore_distributed_state: not a distributed world");
  }
  // Call at the end of the catch block of a step: rethrows the exception being handled. In a
  // distributed world, a failure of this rank alone first meets the other ranks at their next
  // agreement, so that they fail too instead of waiting for it (core/rank_agreement.h).
  virtual void rethrow_step_failure() const { throw; }

  // ---- the device interop tier (include/sph_cuda.h); a backend whose particles live in host
  // memory refuses it with the defaults below ---------------------------------------------------
  // Where an attribute lives in device memory; the pointer stays valid until reserve() grows
  // the backend (the view's epoch changes then too).
  virtual DeviceAttributeView device_attribute(AttributeKind) const { throw unsupported_interop(); }
  // Increments on every call that changes particle data (append, frames, rollbacks).
  virtual uint64_t data_epoch() const { throw unsupported_interop(); }
  // A restore replaces a world's backend with this one: its epoch continues past `previous`'s, so
  // a view taken before the restore (its buffers freed with the old backend) never matches.
  virtual void continue_data_epoch(const Backend& /*previous*/) {}
  // A restore replaces a world's backend with this one: it takes over what `previous` computed
  // from the assets and may still use (the CPU backend's boundary-density maps, keyed by asset
  // and version, so a map of an asset the restored world does not use is never read). Must not
  // throw (it runs after the restore can no longer fail). A backend without such caches does
  // nothing; the CUDA backend computes its maps again at the next step.
  virtual void adopt_asset_caches(Backend& /*previous*/) noexcept {}
  virtual int device_ordinal() const { throw unsupported_interop(); }
  virtual void* device_stream() const { throw unsupported_interop(); }  // a cudaStream_t
  // Records a caller-owned cudaEvent_t on the backend's stream / makes the stream wait for one.
  virtual void record_device_event(void* /*event*/) const { throw unsupported_interop(); }
  virtual void wait_device_event(void* /*event*/) const { throw unsupported_interop(); }
  // The backend's later work waits for what the caller's stream (a cudaStream_t; null: the
  // legacy default stream) holds now / the caller's stream waits for the backend's work so far.
  virtual void order_after_stream(void* /*stream*/) const { throw unsupported_interop(); }
  virtual void order_stream_after(void* /*stream*/) const { throw unsupported_interop(); }

 protected:
  static Error unsupported_interop() {
    return Error(
        Status::Unsupported,
        "world: its particles live in host memory; the interop calls of sph_cuda.h need a world on a "
        "CUDA context");
  }
};

}  // namespace sph
