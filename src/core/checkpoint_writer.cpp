// SPDX-License-Identifier: MIT
// Writes a world as a checkpoint (layout: checkpoint_format.h, docs/checkpoint.md).
#include <map>

#include "byte_io.h"
#include "checkpoint.h"
#include "checkpoint_format.h"
#include "checkpoint_params.h"

namespace sph {
namespace {

using namespace checkpoint;

void write_vec3(ByteWriter& w, const Vec3& v) {
  w.f32(v.x);
  w.f32(v.y);
  w.f32(v.z);
}

void write_pose(ByteWriter& w, const RigidTransform& t) {
  write_vec3(w, t.position);
  w.f32(t.rotation.x);
  w.f32(t.rotation.y);
  w.f32(t.rotation.z);
  w.f32(t.rotation.w);
}

// Every asset the scene references, once each, numbered in first-use order.
class AssetTable {
 public:
  uint32_t index(const std::shared_ptr<const SdfAsset>& asset) {
    if (!asset) return kNoAsset;
    const auto it = index_.find(asset.get());
    if (it != index_.end()) return it->second;
    const uint32_t k = static_cast<uint32_t>(assets_.size());
    index_.emplace(asset.get(), k);
    assets_.push_back(asset.get());
    return k;
  }
  const HostVector<const SdfAsset*>& assets() const { return assets_; }

 private:
  std::map<const SdfAsset*, uint32_t> index_;
  HostVector<const SdfAsset*> assets_;
};

// A section: tag, reserved, length (patched when the body is done), body.
template <class Body>
void section(ByteWriter& w, uint32_t tag_value, Body&& body) {
  w.u32(tag_value);
  w.u32(0);
  const size_t length_at = w.size();
  w.u64(0);
  const size_t start = w.size();
  body();
  w.patch_u64(length_at, w.size() - start);
}

void write_solve(ByteWriter& w, const SolveReport& s) {
  w.u32(s.iterations);
  w.u32(s.iterations_max);
  w.u32(s.capped);
  w.f32(s.error_mean);
  w.f32(s.error_max);
  w.f32(s.largest_max);  // version 9
  w.u32(s.guarded);      // version 13
}

// SPH_FEATURE_SPRINGS worlds only, after the particles: the lowest id still waiting for springs
// and each particle's spring slots (partner storage index or 0xffffffff, rest length).
void write_springs(ByteWriter& w, const ParticleSnapshot& s) {
  const HostVector<uint32_t> link_from = s.carried_as<uint32_t>(kArraySpringLinkFrom);
  w.u32(link_from.empty() ? kNoPendingLinks : link_from[0]);
  w.u32(kSpringSlots);
  for (const SpringList& list : s.carried_as<SpringList>(kArraySprings))
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      w.u32(list.partner[k]);
      w.f32(list.rest[k]);
    }
}

void write_clock(ByteWriter& w, const World& world) {
  const FrameReport& r = world.last_report();
  w.u32(world.next_id());
  w.u32(world.id_tag());  // version 15; 0 (reserved) before
  w.f64(world.simulated_time());
  w.f32(world.last_step_ms());
  w.u32(r.substeps);
  w.u32(r.completed ? 1u : 0u);
  w.f64(r.time_advanced);
  w.f32(r.dt_min);
  w.f32(r.dt_max);
  w.f32(r.max_speed);
  w.f32(r.density_min);
  w.f32(r.density_mean);
  w.f32(r.density_max);
  w.f32(r.neighbors_mean);
  w.u32(r.neighbors_max);
  for (float ms : r.stage_ms) w.f32(ms);
  write_solve(w, r.pressure_solve);
  write_solve(w, r.divergence_solve);
  // What the last step reported, so a loaded world answers the same queries.
  w.u32(static_cast<uint32_t>(world.events().size()));
  for (const Event& e : world.events()) {
    w.u32(static_cast<uint32_t>(e.type));
    w.u32(e.count);
    w.u64(e.object_id);
  }
  w.u32(static_cast<uint32_t>(r.removed_ids.size()));
  for (uint32_t id : r.removed_ids) w.u32(id);
}

void write_particles(ByteWriter& w, const ParticleSnapshot& s) {
  w.u32(static_cast<uint32_t>(s.id.size()));
  w.u32(0);
  w.f32(s.max_speed);
  w.f32(s.max_acceleration);
  for (const Float4& p : s.position) {
    w.f32(p.x);
    w.f32(p.y);
    w.f32(p.z);
    w.f32(p.w);
  }
  for (const Float4& v : s.velocity) {
    w.f32(v.x);
    w.f32(v.y);
    w.f32(v.z);
    w.f32(v.w);
  }
  for (uint32_t id : s.id) w.u32(id);
  for (float d : s.density) w.f32(d);
  // Normalised density only: each particle's carried factor (NaN: not resolved yet).
  for (float d : s.carried_as<float>(kArrayDensityFactor)) w.f32(d);
  // DFSPH only: the warm starts of its two solves.
  for (float k : s.carried_as<float>(kArrayDfsphPressure)) w.f32(k);
  for (float k : s.carried_as<float>(kArrayDfsphDivergencePressure)) w.f32(k);
  // SPH_FEATURE_USER_ATTRIBUTE only: each particle's value.
  for (uint32_t a : s.carried_as<uint32_t>(kArrayUserAttribute)) w.u32(a);
}

void write_asset(ByteWriter& w, const SdfAsset& a) {
  w.u32(static_cast<uint32_t>(a.nx()));
  w.u32(static_cast<uint32_t>(a.ny()));
  w.u32(static_cast<uint32_t>(a.nz()));
  w.u32((a.velocity().empty() ? 0u : kAssetHasVelocity) | (a.friction().empty() ? 0u : kAssetHasFriction));
  for (float m : a.index_to_local().m) w.f32(m);
  for (float d : a.distance()) w.f32(d);
  for (const Vec3& v : a.velocity()) write_vec3(w, v);
  for (float f : a.friction()) w.f32(f);
}

// The slot table of one kind of object: every slot (generation, live flag, body), then the
// free list in its order, so ids and the ids of later insertions are the same after a load.
template <class T, class Body>
void write_slots(ByteWriter& w, const SlotMap<T>& map, Body&& body) {
  w.u32(map.slot_count());
  for (uint32_t i = 0; i < map.slot_count(); ++i) {
    w.u32(map.generation_at(i));
    const T* value = map.value_at(i);
    w.u32(value ? 1u : 0u);
    if (value) body(*value);
  }
  w.u32(static_cast<uint32_t>(map.free_slots().size()));
  for (uint32_t slot : map.free_slots()) w.u32(slot);
}

void write_particle_section(ByteWriter& w, const World& world, const ParticleSnapshot& particles,
                            bool rank_part) {
  write_particles(w, particles);
  if (world.config().features & kFeatureSprings) write_springs(w, particles);
  if (rank_part)
    for (uint64_t key : particles.carried_as<uint64_t>(kArrayDistributedSortKey)) w.u64(key);
}

}  // namespace

void write_config(ByteWriter& w, const WorldConfig& c) {
  w.u32(c.capacity);
  w.u32(c.features);
  w.u32(static_cast<uint32_t>(c.integrator));
  w.u32(static_cast<uint32_t>(c.viscosity_method));
  w.u32(static_cast<uint32_t>(c.equation_of_state));
  w.f32(c.particle_spacing);
  w.f32(c.kernel_radius);
  w.f32(c.rest_density);
  w.f32(c.particle_mass);
  w.u32(static_cast<uint32_t>(c.solver));
  w.u32(c.max_capacity);  // version 5
}

HostVector<uint8_t> write_checkpoint(const World& world, const CheckpointOrigin& origin) {
  if (world.backend().distributed() != origin.rank_part)
    throw Error(origin.rank_part ? Status::Internal : Status::Unsupported,
                origin.rank_part ? "write_checkpoint: a rank's part of a world that is not distributed"
                                 : "world: a distributed world saves one checkpoint per rank and a manifest: "
                                   "sph_mpi_world_save_file on every rank (sph_mpi.h)");
  // Asset indices first: the asset section precedes the objects that refer to it.
  AssetTable assets;
  world.colliders().for_each([&](uint64_t, const Collider& c) { assets.index(c.sdf); });
  world.sources().for_each([&](uint64_t, const Source& s) { assets.index(s.region); });
  world.sinks().for_each([&](uint64_t, const Sink& s) { assets.index(s.region); });
  world.force_fields().for_each([&](uint64_t, const ForceField& f) {
    assets.index(f.region);
    assets.index(f.grid);
  });
  const ParticleSnapshot particles = world.backend().export_particles();

  ByteWriter w;
  for (uint8_t b : kMagic) w.u8(b);  // (not bytes(): GCC 12 flags its insert into an empty vector here)
  w.u32(kFormatVersion);
  w.u32(origin.rank_part ? kFlagRankPart : 0u);
  w.u32(origin.backend);
  w.u32(origin.library_version);
  w.u64(0);  // payload size, patched below
  w.u64(0);  // checksum, patched below
  w.u32(kSectionCount);
  w.u32(0);

  section(w, kSectionOrder[0].tag, [&] { write_config(w, world.config()); });
  section(w, kSectionOrder[1].tag, [&] { write_params(w, world.params()); });
  section(w, kSectionOrder[2].tag, [&] { write_clock(w, world); });
  section(w, kSectionOrder[3].tag, [&] { write_particle_section(w, world, particles, origin.rank_part); });
  section(w, kSectionOrder[4].tag, [&] {
    w.u32(static_cast<uint32_t>(assets.assets().size()));
    for (const SdfAsset* a : assets.assets()) write_asset(w, *a);
  });
  section(w, kSectionOrder[5].tag, [&] {
    write_slots(w, world.colliders(), [&](const Collider& c) {
      w.u32(assets.index(c.sdf));
      write_pose(w, c.pose);
      w.u32(c.target ? 1u : 0u);
      if (c.target) write_pose(w, *c.target);
      w.f32(c.material.restitution);
      w.f32(c.material.friction);
      w.f32(c.material.stickiness);
      w.u32(c.inverted ? 1u : 0u);
      write_vec3(w, c.load_point);
      w.f32(c.load_threshold);
    });
  });
  section(w, kSectionOrder[6].tag, [&] {
    write_slots(w, world.sources(), [&](const Source& s) {
      w.u32(assets.index(s.region));
      write_pose(w, s.pose);
      w.u32(static_cast<uint32_t>(s.mode));
      w.f32(s.spacing);
      w.f32(s.min_distance);
      write_vec3(w, s.velocity);
      w.u32(s.velocity_from_field ? 1u : 0u);
      w.f32(s.rate);
      if (world.config().features & kFeatureUserAttribute) w.u32(s.user_attribute);
      w.f64(s.rate_budget);
      w.u32(s.done ? 1u : 0u);
      w.u32(static_cast<uint32_t>(s.lattice.size()));
      for (const Vec3& p : s.lattice) write_vec3(w, p);
    });
  });
  section(w, kSectionOrder[7].tag, [&] {
    write_slots(w, world.sinks(), [&](const Sink& s) {
      w.u32(static_cast<uint32_t>(s.mode));
      w.u32(assets.index(s.region));
      write_pose(w, s.pose);
      write_vec3(w, s.bounds_min);
      write_vec3(w, s.bounds_max);
    });
  });
  section(w, kSectionOrder[8].tag, [&] {
    write_slots(w, world.force_fields(), [&](const ForceField& f) {
      w.u32(static_cast<uint32_t>(f.kind));
      w.u32(assets.index(f.region));
      w.u32(assets.index(f.grid));
      write_pose(w, f.pose);
      write_vec3(w, f.vector);
      w.f32(f.strength);
      w.f32(f.falloff_radius);
    });
  });
  section(w, kSectionOrder[9].tag, [&] {
    // The probes as placed (their readings are the last step's output, not state).
    write_slots(w, world.probes(), [&](const Probe& p) {
      w.u32(p.gauge ? 1u : 0u);
      w.u32(p.every_substep ? 1u : 0u);
      write_vec3(w, p.position);
      write_vec3(w, p.direction);
      w.f32(p.length);
      w.u32(p.sample_count);
      w.f32(p.pressure_threshold);
    });
  });

  HostVector<uint8_t>& bytes = w.buffer();
  w.patch_u64(24, bytes.size() - kHeaderSize);
  Fnv1a64 sum;
  sum.add(bytes.data(), kChecksumOffset);
  sum.add(bytes.data() + kChecksumOffset + 8, bytes.size() - kChecksumOffset - 8);
  w.patch_u64(kChecksumOffset, sum.value());
  return std::move(bytes);
}

}  // namespace sph
