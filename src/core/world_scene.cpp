// SPDX-License-Identifier: MIT
// The world's entry points for its scene: colliders, sources, sinks and force fields made from
// specs (rules in scene_build.h), their setters, and the restore of a saved scene.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "field_checks.h"
#include "field_error.h"
#include "pose_rules.h"
#include "position_reach.h"
#include "scene_build.h"
#include "status.h"
#include "world.h"

namespace sph {
namespace {

constexpr size_t kMaxObjectsPerKind = 65536;
constexpr uint64_t kMaxSourceLatticePoints = 1ull << 28;

template <class T>
void require_room(const SlotMap<T>& map, const char* kind) {
  if (map.size() >= kMaxObjectsPerKind)
    throw Error(Status::Capacity, std::string("a world holds at most 65536 ") + kind);
}

template <class T>
void remove(SlotMap<T>& map, uint64_t id) {
  if (id == 0) return;
  if (!map.erase(id)) throw Error(Status::InvalidHandle, "id: is stale or not of this world");
}

}  // namespace

void World::set_id_tag(uint16_t tag) {
  colliders_.set_world_tag(tag);
  sources_.set_world_tag(tag);
  sinks_.set_world_tag(tag);
  force_fields_.set_world_tag(tag);
  probes_.set_world_tag(tag);
}

namespace {

template <class T>
bool same_bits(const HostVector<T>& a, const HostVector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_asset(const SdfAsset& a, const SdfAsset& b) {
  return a.nx() == b.nx() && a.ny() == b.ny() && a.nz() == b.nz() &&
         std::memcmp(&a.index_to_local(), &b.index_to_local(), sizeof(Affine3x4)) == 0 &&
         same_bits(a.distance(), b.distance()) && same_bits(a.velocity(), b.velocity()) &&
         same_bits(a.friction(), b.friction());
}

// Each live object of `mine` whose namesake in `before` uses an asset of the same bits takes it.
template <class T>
void take_same_assets(SlotMap<T>& mine, const SlotMap<T>& before, std::shared_ptr<const SdfAsset> T::*asset) {
  mine.for_each([&](uint64_t id, T& object) {
    const T* old = before.find(id);
    if (!old) return;
    const std::shared_ptr<const SdfAsset>& theirs = (*old).*asset;
    std::shared_ptr<const SdfAsset>& ours = object.*asset;
    if (ours && theirs && ours != theirs && same_asset(*ours, *theirs)) ours = theirs;
  });
}

using AssetList = std::vector<std::shared_ptr<const SdfAsset>>;

// The distinct assets the objects of `map` use, in the map's order.
template <class T>
void add_assets(const SlotMap<T>& map, std::shared_ptr<const SdfAsset> T::*asset, AssetList& out) {
  map.for_each([&](uint64_t, const T& object) {
    const std::shared_ptr<const SdfAsset>& a = object.*asset;
    if (a && std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
  });
}

// Each live object of `mine` still holding an asset that is none of `theirs` takes the first of
// them with the same bits (an object the restore brought back, whose namesake was gone).
template <class T>
void take_any_same_asset(SlotMap<T>& mine, const AssetList& theirs,
                         std::shared_ptr<const SdfAsset> T::*asset) {
  mine.for_each([&](uint64_t, T& object) {
    std::shared_ptr<const SdfAsset>& ours = object.*asset;
    if (!ours || std::find(theirs.begin(), theirs.end(), ours) != theirs.end()) return;
    for (const std::shared_ptr<const SdfAsset>& candidate : theirs)
      if (same_asset(*ours, *candidate)) {
        ours = candidate;
        return;
      }
  });
}

}  // namespace

void World::keep_caller_assets(const World& before) {
  take_same_assets(colliders_, before.colliders_, &Collider::sdf);
  take_same_assets(sources_, before.sources_, &Source::region);
  take_same_assets(sinks_, before.sinks_, &Sink::region);
  take_same_assets(force_fields_, before.force_fields_, &ForceField::region);
  // Then an object with no namesake in `before` (an undo of its deletion) takes any asset of
  // `before`'s objects with the same bits: the caller's asset another object still uses.
  AssetList theirs;
  add_assets(before.colliders_, &Collider::sdf, theirs);
  add_assets(before.sources_, &Source::region, theirs);
  add_assets(before.sinks_, &Sink::region, theirs);
  add_assets(before.force_fields_, &ForceField::region, theirs);
  if (theirs.empty()) return;
  take_any_same_asset(colliders_, theirs, &Collider::sdf);
  take_any_same_asset(sources_, theirs, &Source::region);
  take_any_same_asset(sinks_, theirs, &Sink::region);
  take_any_same_asset(force_fields_, theirs, &ForceField::region);
}

void World::keep_issued_ids(const World& before) {
  colliders_.keep_issued(before.colliders_);
  sources_.keep_issued(before.sources_);
  sinks_.keep_issued(before.sinks_);
  force_fields_.keep_issued(before.force_fields_);
  probes_.keep_issued(before.probes_);
}

uint64_t World::add_collider(const ColliderSpec& spec) {
  Collider c = make_collider(spec);
  require_room(colliders_, "colliders");
  return colliders_.insert(std::move(c));
}

uint64_t World::add_source(const SourceSpec& spec) {
  Source s = make_source(spec, config_);
  s.lattice = lattice_inside(*s.region, s.spacing, kMaxSourceLatticePoints);
  s.lattice_bounds = lattice_box(s.lattice);
  const std::string reach = lattice_reach_problem(s.lattice_bounds, s.pose, config_.particle_spacing);
  if (!reach.empty()) throw FieldError(Status::InvalidArgument, "transform", reach);
  require_room(sources_, "sources");
  return sources_.insert(std::move(s));
}

uint64_t World::add_sink(const SinkSpec& spec) {
  Sink s = make_sink(spec);
  require_room(sinks_, "sinks");
  return sinks_.insert(std::move(s));
}

uint64_t World::add_force_field(const ForceFieldSpec& spec) {
  ForceField f = make_force_field(spec);
  require_room(force_fields_, "force fields");
  return force_fields_.insert(std::move(f));
}

void World::remove_collider(uint64_t id) { remove(colliders_, id); }
void World::remove_source(uint64_t id) { remove(sources_, id); }
void World::remove_sink(uint64_t id) { remove(sinks_, id); }
void World::remove_force_field(uint64_t id) { remove(force_fields_, id); }

void World::set_collider_target(uint64_t id, const RigidTransform& target) {
  Collider& c = colliders_.at(id);
  require_pose(target, "target");
  c.target = target;
}

void World::teleport_collider(uint64_t id, const RigidTransform& pose) {
  Collider& c = colliders_.at(id);
  require_pose(pose, "transform");
  c.pose = pose;
  c.target.reset();
}

void World::set_collider_material(uint64_t id, const ColliderMaterial& material) {
  Collider& c = colliders_.at(id);
  check_collider_material(material);
  c.material = material;
}

void World::set_collider_load_point(uint64_t id, Vec3 point) {
  Collider& c = colliders_.at(id);
  require_finite_vec3_field(point, "point");
  c.load_point = point;
}

void World::set_collider_load_threshold(uint64_t id, float threshold) {
  Collider& c = colliders_.at(id);
  require_non_negative_field(threshold, "force");
  c.load_threshold = threshold;
}

void World::set_source_pose(uint64_t id, const RigidTransform& pose) {
  Source& s = sources_.at(id);
  require_pose(pose, "transform");
  const std::string reach = lattice_reach_problem(s.lattice_bounds, pose, config_.particle_spacing);
  if (!reach.empty()) throw FieldError(Status::InvalidArgument, "transform", reach);
  s.pose = pose;
}

void World::set_force_field_pose(uint64_t id, const RigidTransform& pose) {
  ForceField& f = force_fields_.at(id);
  require_pose(pose, "transform");
  f.pose = pose;
}

const Collider& World::collider(uint64_t id) const { return colliders_.at(id); }

void World::restore_scene(SceneTables tables) {
  colliders_.restore(std::move(tables.colliders));
  sources_.restore(std::move(tables.sources));
  sinks_.restore(std::move(tables.sinks));
  force_fields_.restore(std::move(tables.force_fields));
}

}  // namespace sph
