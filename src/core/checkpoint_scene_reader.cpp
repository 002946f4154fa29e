// SPDX-License-Identifier: MIT
#include "checkpoint_scene_reader.h"

#include <cmath>
#include <string>
#include <utility>

#include "../physics/probe_sampling.h"
#include "checkpoint_fields.h"
#include "field_error.h"
#include "number_text.h"
#include "pose_rules.h"
#include "position_reach.h"
#include "scene_build.h"
#include "sdf_limits.h"

namespace sph {
namespace {

using namespace checkpoint_read;

std::shared_ptr<SdfAsset> read_asset(ByteReader& r, uint32_t index) {
  const std::string name = "asset " + std::to_string(index);
  uint32_t dims[3];
  for (uint32_t& d : dims) {
    d = r.u32();
    if (d == 0 || d > kMaxSdfDim)
      corrupt(r.what() + ": " + name + " has a dimension of " + std::to_string(d));
  }
  const uint64_t n = uint64_t{dims[0]} * dims[1] * dims[2];
  if (n > kMaxSdfVoxels) corrupt(r.what() + ": " + name + " has more than 2^31 voxels");
  const uint32_t channels = r.u32();
  if (channels & ~(kAssetHasVelocity | kAssetHasFriction))
    corrupt(r.what() + ": " + name + " has unknown channel bits " + hex32(channels));
  Affine3x4 affine;
  for (float& m : affine.m) m = finite(r, name + " index_to_local");
  const uint64_t floats_per_voxel =
      1 + ((channels & kAssetHasVelocity) ? 3 : 0) + ((channels & kAssetHasFriction) ? 1 : 0);
  r.need_elements(n, floats_per_voxel * sizeof(float), "voxels");  // before any allocation
  std::shared_ptr<SdfAsset> asset;
  try {
    asset = make_sdf_asset(static_cast<int32_t>(dims[0]), static_cast<int32_t>(dims[1]),
                           static_cast<int32_t>(dims[2]), affine);
  } catch (const Error& e) {
    corrupt(r.what() + ": " + name + ": " + e.what());
  }
  const std::string where = name + ": voxel";
  HostVector<float>& distance = asset->distance();
  for (uint64_t i = 0; i < n; ++i) distance[i] = bulk_finite(r, where.c_str(), static_cast<uint32_t>(i));
  if (channels & kAssetHasVelocity) {
    asset->velocity().resize(n);
    HostVector<Vec3>& velocity = asset->velocity();
    // (Any finite values: a force field's grid keeps its accelerations in this channel, which may
    // be as large as a float holds; a source's region is held to particle speeds in read_source.)
    for (uint64_t i = 0; i < n; ++i) velocity[i] = bulk_vec3(r, where.c_str(), static_cast<uint32_t>(i));
  }
  if (channels & kAssetHasFriction) {
    asset->friction().resize(n);
    HostVector<float>& friction = asset->friction();
    for (uint64_t i = 0; i < n; ++i) {
      friction[i] = bulk_finite(r, where.c_str(), static_cast<uint32_t>(i));
      if (friction[i] < 0.0f)
        corrupt(r.what() + ": " + where + " " + std::to_string(i) + " has a negative friction");
    }
  }
  return asset;
}

using Assets = CheckpointAssets;

// An asset of the table, or none; whether the object needs one is the scene's rule.
std::shared_ptr<const SdfAsset> asset_ref(ByteReader& r, const Assets& assets, const std::string& name) {
  const uint32_t k = r.u32();
  if (k == kNoAsset) return nullptr;
  if (k >= assets.size())
    corrupt(r.what() + ": " + name + " refers to asset " + std::to_string(k) + " of " +
            std::to_string(assets.size()));
  return assets[k];
}

// The slot table of one kind of object (see write_slots); read_value reads one live body.
template <class T, class ReadValue>
SlotTable<T> read_slots(ByteReader& r, ReadValue&& read_value) {
  SlotTable<T> t;
  const uint32_t slots = r.u32();
  if (slots > kMaxObjectSlots) corrupt(r.what() + ": " + std::to_string(slots) + " slots, more than 65536");
  r.need_elements(slots, 2 * sizeof(uint32_t), "slots");
  t.generations.resize(slots);
  t.values.resize(slots);
  uint32_t dead = 0;
  for (uint32_t i = 0; i < slots; ++i) {
    const std::string name = "slot " + std::to_string(i);
    t.generations[i] = r.u32();
    if (t.generations[i] == 0 || t.generations[i] > 0xffffffu)
      corrupt(r.what() + ": " + name + " has generation " + std::to_string(t.generations[i]));
    if (flag(r, name + " live"))
      t.values[i] = read_value(name);
    else
      ++dead;
  }
  const uint32_t free_count = r.u32();
  if (free_count != dead)
    corrupt(r.what() + ": the free list has " + std::to_string(free_count) + " slots, but " +
            std::to_string(dead) + " slots are empty");
  HostVector<char> seen(slots, 0);
  t.free_list.resize(free_count);
  for (uint32_t& slot : t.free_list) {
    slot = r.u32();
    if (slot >= slots || t.values[slot] || seen[slot])
      corrupt(r.what() + ": the free list names slot " + std::to_string(slot) +
              ", which is not a distinct empty slot");
    seen[slot] = 1;
  }
  return t;
}

// Runs one of the scene's rules (scene_build.h, pose_rules.h: the same the world's entry
// points apply to callers) on what the file holds; a violation is corrupt data, named by slot.
template <class Check>
auto by_scene_rules(ByteReader& r, const std::string& name, Check&& check) -> decltype(check()) {
  try {
    return with_field_prefix(name + " ", std::forward<Check>(check));
  } catch (const Error& e) {
    corrupt(r.what() + ": " + e.what());
  }
}

Vec3 finite_vec3(ByteReader& r, const std::string& name) {
  Vec3 v;
  v.x = finite(r, name);
  v.y = finite(r, name);
  v.z = finite(r, name);
  return v;
}

Collider read_collider(ByteReader& r, const Assets& assets, uint32_t version, const std::string& name) {
  ColliderSpec spec;
  spec.sdf = asset_ref(r, assets, name + " SDF");
  spec.pose = raw_pose(r);
  std::optional<RigidTransform> target;
  if (flag(r, name + " has target")) target = raw_pose(r);
  spec.material.restitution = r.f32();
  spec.material.friction = r.f32();
  spec.material.stickiness = r.f32();
  spec.inverted = flag(r, name + " inverted") != 0;
  Vec3 load_point{0.0f, 0.0f, 0.0f};
  if (version >= kFirstProbeVersion) load_point = finite_vec3(r, name + " load point");
  const float load_threshold =
      version >= kFirstThresholdVersion ? non_negative(r, name + " load threshold") : 0.0f;
  Collider c = by_scene_rules(r, name, [&] { return make_collider(spec); });
  if (target) by_scene_rules(r, name, [&] { require_pose(*target, "target"); });
  c.target = target;
  c.load_point = load_point;
  c.load_threshold = load_threshold;
  return c;
}

// The rules of World::add_probe (world_probes.cpp) on what the file holds.
Probe read_probe(ByteReader& r, uint32_t version, const std::string& name) {
  Probe p;
  p.gauge = flag(r, name + " gauge") != 0;
  p.every_substep = flag(r, name + " every substep") != 0;
  p.position = finite_vec3(r, name + " position");
  p.direction = finite_vec3(r, name + " direction");
  p.length = finite(r, name + " length");
  p.sample_count = r.u32();
  const float d2 = length_squared(p.direction);
  if (!(d2 == 0.0f || std::fabs(d2 - 1.0f) < 1e-3f))
    corrupt(r.what() + ": " + name + " has a direction neither zero nor of unit length");
  if (p.gauge ? !(p.length > 0.0f) || p.sample_count == 0 || p.sample_count > kMaxGaugeSamples
              : p.length != 0.0f || p.sample_count != 1u || d2 != 0.0f)
    corrupt(r.what() + ": " + name + " has a length or sample count its kind does not allow");
  if (version >= kFirstThresholdVersion) p.pressure_threshold = non_negative(r, name + " pressure threshold");
  return p;
}

Source read_source(ByteReader& r, const Assets& assets, const WorldConfig& config, uint32_t version,
                   const std::string& name) {
  SourceSpec spec;
  spec.region = asset_ref(r, assets, name + " region");
  spec.pose = raw_pose(r);
  spec.mode = static_cast<SourceMode>(below(r, 2, name + " mode"));
  spec.spacing = r.f32();
  spec.min_distance = r.f32();
  spec.velocity = raw_vec3(r);
  spec.velocity_from_field = flag(r, name + " velocity from field") != 0;
  spec.rate = r.f32();
  if (config.features & kFeatureUserAttribute) spec.user_attribute = r.u32();
  // Stored values are resolved: a zero here would be read as "the default" by the rules.
  if (spec.spacing == 0.0f || spec.min_distance == 0.0f)
    corrupt(r.what() + ": " + name + " spacing or min distance is 0 (never written)");
  Source s = by_scene_rules(r, name, [&] { return make_source(spec, config); });
  // sph_sdf_create's and sph_sdf_update's rule on a velocity channel, for the region whose
  // velocities this source gives its particles.
  if (spec.velocity_from_field)
    for (const Vec3& v : spec.region->velocity())
      if (!speed_fits_float(v)) corrupt(r.what() + ": " + name + " region has a speed above 1.8e19 m/s");
  s.rate_budget = r.f64();
  // A budget grows by at most rate x frame time per step; far below the size_t range. Since
  // version 14 it may be a debt (World::step: a frame that stopped early gives back the credit
  // of the time it did not simulate), at most kMaxSourceDebt.
  const double lowest = version >= kFirstSourceDebtVersion ? -kMaxSourceDebt : 0.0;
  if (!std::isfinite(s.rate_budget) || s.rate_budget < lowest || s.rate_budget > kMaxSourceCredit)
    corrupt(r.what() + ": " + name + " rate budget is outside [" + number_text(lowest) + ", " +
            number_text(kMaxSourceCredit) + "]");
  s.done = flag(r, name + " done") != 0;
  const uint32_t points = r.u32();
  r.need_elements(points, 3 * sizeof(float), "lattice points");
  s.lattice.resize(points);
  const std::string where = name + " lattice point";
  for (uint32_t i = 0; i < points; ++i) s.lattice[i] = bulk_vec3(r, where.c_str(), i);
  // World::add_source's and set_source_pose's reach.
  s.lattice_bounds = lattice_box(s.lattice);
  const std::string reach = lattice_reach_problem(s.lattice_bounds, s.pose, config.particle_spacing);
  if (!reach.empty()) corrupt(r.what() + ": " + name + " transform " + reach);
  return s;
}

Sink read_sink(ByteReader& r, const Assets& assets, const std::string& name) {
  SinkSpec spec;
  spec.mode = static_cast<SinkMode>(below(r, 2, name + " mode"));
  spec.region = asset_ref(r, assets, name + " region");
  spec.pose = raw_pose(r);
  spec.bounds_min = raw_vec3(r);
  spec.bounds_max = raw_vec3(r);
  return by_scene_rules(r, name, [&] { return make_sink(spec); });
}

ForceField read_force_field(ByteReader& r, const Assets& assets, const std::string& name) {
  ForceFieldSpec spec;
  spec.kind = static_cast<ForceFieldKind>(below(r, 4, name + " kind"));
  spec.region = asset_ref(r, assets, name + " region");
  spec.grid = asset_ref(r, assets, name + " grid");
  spec.pose = raw_pose(r);
  spec.vector = raw_vec3(r);
  spec.strength = r.f32();
  spec.falloff_radius = r.f32();
  return by_scene_rules(r, name, [&] { return make_force_field(spec); });
}

}  // namespace

CheckpointAssets read_checkpoint_assets(ByteReader& r) {
  const uint32_t asset_count = r.u32();
  r.need_elements(asset_count, 16 + 12 * sizeof(float) + sizeof(float), "assets");
  CheckpointAssets assets;
  for (uint32_t k = 0; k < asset_count; ++k) assets.push_back(read_asset(r, k));
  return assets;
}

SlotTable<Collider> read_checkpoint_colliders(ByteReader& r, const CheckpointAssets& assets,
                                              uint32_t version) {
  return read_slots<Collider>(
      r, [&](const std::string& n) { return read_collider(r, assets, version, "collider " + n); });
}

SlotTable<Source> read_checkpoint_sources(ByteReader& r, const CheckpointAssets& assets,
                                          const WorldConfig& config, uint32_t version) {
  return read_slots<Source>(
      r, [&](const std::string& n) { return read_source(r, assets, config, version, "source " + n); });
}

SlotTable<Sink> read_checkpoint_sinks(ByteReader& r, const CheckpointAssets& assets) {
  return read_slots<Sink>(r, [&](const std::string& n) { return read_sink(r, assets, "sink " + n); });
}

SlotTable<ForceField> read_checkpoint_force_fields(ByteReader& r, const CheckpointAssets& assets) {
  return read_slots<ForceField>(
      r, [&](const std::string& n) { return read_force_field(r, assets, "force field " + n); });
}

SlotTable<Probe> read_checkpoint_probes(ByteReader& r, uint32_t version) {
  SlotTable<Probe> probes =
      read_slots<Probe>(r, [&](const std::string& n) { return read_probe(r, version, "probe " + n); });
  // World::add_probe's limit on the points of all probes together.
  uint64_t points = 0;
  for (const std::optional<Probe>& p : probes.values)
    if (p) points += p->points();
  if (points > kMaxProbePoints)
    corrupt(r.what() + ": the probes sample " + std::to_string(points) + " points, more than " +
            std::to_string(kMaxProbePoints));
  return probes;
}

}  // namespace sph
