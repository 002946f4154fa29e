// SPDX-License-Identifier: MIT
// The world's entry points that change particles already in it: ranges of positions,
// velocities and user attributes, and removal by id. Each goes through the backend's whole
// particle state (export, edit, import: the path checkpoints take, so it is exact and the same
// on every backend) after checking everything, so an error changes nothing.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "field_checks.h"
#include "world.h"

namespace sph {
namespace {

// What the step controller carries as the max speed: sqrt of the largest |v|^2, as a backend
// computes it when the velocities change under it (the max is order-free, so this is exact).
float max_speed_of(const HostVector<Float4>& velocity) {
  float v2max = 0.0f;
  for (const Float4& v : velocity) v2max = std::max(v2max, length_squared(xyz(v)));
  return std::sqrt(v2max);
}

// The bytes of the particles that stay (kept[i] for particle i) of an array of
// per_particle_bytes per particle.
HostVector<unsigned char> kept_bytes(const HostVector<unsigned char>& bytes, const HostVector<char>& kept,
                                     size_t per_particle_bytes) {
  HostVector<unsigned char> out;
  out.reserve(bytes.size());
  for (size_t i = 0; i < kept.size(); ++i)
    if (kept[i])
      out.insert(out.end(), bytes.begin() + i * per_particle_bytes,
                 bytes.begin() + (i + 1) * per_particle_bytes);
  return out;
}

template <class T>
HostVector<T> kept_values(const HostVector<T>& values, const HostVector<char>& kept) {
  HostVector<T> out;
  out.reserve(values.size());
  for (size_t i = 0; i < kept.size(); ++i)
    if (kept[i]) out.push_back(values[i]);
  return out;
}

}  // namespace

void World::require_particle_range(uint32_t first, uint64_t count) const {
  const uint32_t total = particle_count();
  if (first > total || count > total - first)
    throw Error(Status::InvalidArgument, "first/count: particles [" + std::to_string(first) + ", " +
                                             std::to_string(first + count) + ") pass the particle count " +
                                             std::to_string(total));
}

void World::set_vectors(AttributeKind kind, uint32_t first, const HostVector<Vec3>& values) {
  if (kind != AttributeKind::Position && kind != AttributeKind::Velocity)
    throw Error(Status::Internal, "set_vectors: not a position or velocity");
  require_particle_range(first, values.size());
  if (kind == AttributeKind::Velocity)
    for (size_t i = 0; i < values.size(); ++i)
      require_particle_velocity_field(values[i], "src[" + std::to_string(i) + "]");
  if (values.empty()) return;
  ParticleSnapshot s = backend_->export_particles();
  HostVector<Float4>& target = kind == AttributeKind::Position ? s.position : s.velocity;
  if (kind == AttributeKind::Position)
    for (size_t i = 0; i < values.size(); ++i) {
      // A step may carry a particle beyond the positions' reach (position_reach.h: nothing stops
      // free flight there); writing its own position back keeps a read-modify-write of a range
      // working, while moving it, or another particle, to such a place is refused.
      const Vec3 current = xyz(target[first + i]);
      const bool unchanged = std::memcmp(&current, &values[i], sizeof(Vec3)) == 0;
      const std::string problem = position_problem(values[i], !unchanged);
      if (!problem.empty())
        throw FieldError(Status::InvalidArgument, "src[" + std::to_string(i) + "]", problem);
    }
  for (size_t i = 0; i < values.size(); ++i) {
    Float4& record = target[first + i];
    record = make_float4_record(values[i], record.w);  // w (pressure, 1/density) stays
  }
  if (kind == AttributeKind::Velocity) s.max_speed = max_speed_of(s.velocity);
  backend_->import_particles(s);
}

void World::set_user_attributes(uint32_t first, const HostVector<uint32_t>& values) {
  if (!(config_.features & kFeatureUserAttribute))
    throw Error(Status::FeatureDisabled,
                "world: SPH_FEATURE_USER_ATTRIBUTE is not enabled in its sph_world_def (SPH_ATTRIBUTE_USER)");
  require_particle_range(first, values.size());
  if (values.empty()) return;
  ParticleSnapshot s = backend_->export_particles();
  HostVector<uint32_t> attribute = s.carried_as<uint32_t>(kArrayUserAttribute);
  if (attribute.size() != s.id.size())
    throw Error(Status::Internal, "set_user_attributes: the backend exported no user attributes");
  std::copy(values.begin(), values.end(), attribute.begin() + first);
  s.set_carried(kArrayUserAttribute, attribute);
  backend_->import_particles(s);
}

void World::remove_particles(const HostVector<uint32_t>& ids) {
  if (ids.empty()) return;
  if (backend_->distributed())
    throw Error(Status::Unsupported,
                "remove_particles: the world is distributed over MPI ranks (sph_mpi.h), where removing "
                "particles by id is not supported (the ranks' sort keys would lose their particles)");
  ParticleSnapshot s = backend_->export_particles();
  const size_t n = s.id.size();
  // Index of each id (ids are unique within a world), then every requested id checked in the
  // order given, so the error names the first bad one.
  HostVector<std::pair<uint32_t, uint32_t>> by_id(n);
  for (size_t i = 0; i < n; ++i) by_id[i] = {s.id[i], static_cast<uint32_t>(i)};
  std::sort(by_id.begin(), by_id.end());
  constexpr uint32_t kNotAsked = 0xffffffffu;
  HostVector<uint32_t> asked_at(n, kNotAsked);  // per particle: where in ids it was asked for
  for (size_t k = 0; k < ids.size(); ++k) {
    const std::string field = "ids[" + std::to_string(k) + "]";
    const auto it = std::lower_bound(by_id.begin(), by_id.end(), std::make_pair(ids[k], 0u));
    if (it == by_id.end() || it->first != ids[k])
      throw FieldError(Status::InvalidArgument, field,
                       std::to_string(ids[k]) + " names no particle of the world (never issued, or removed)");
    uint32_t& at = asked_at[it->second];
    if (at != kNotAsked)
      throw FieldError(Status::InvalidArgument, field,
                       std::to_string(ids[k]) + " appears twice (first at ids[" + std::to_string(at) + "])");
    at = static_cast<uint32_t>(k);
  }
  HostVector<char> kept(n);
  HostVector<uint32_t> new_index_of_old(n, 0xffffffffu);  // ParticleArraySpec::rewrite_indices
  uint32_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    kept[i] = asked_at[i] == kNotAsked;
    if (kept[i]) new_index_of_old[i] = next++;
  }
  ParticleSnapshot out;
  out.position = kept_values(s.position, kept);
  out.velocity = kept_values(s.velocity, kept);
  out.id = kept_values(s.id, kept);
  out.density = kept_values(s.density, kept);
  out.max_speed = max_speed_of(out.velocity);
  out.max_acceleration = s.max_acceleration;
  const std::vector<ParticleArraySpec> specs = method_particle_arrays(config_);
  for (const CarriedArray& a : s.carried) {
    const ParticleArraySpec* spec = find_array_spec(specs, a.name.c_str());
    if (!spec) throw Error(Status::Internal, "remove_particles: the backend carries '" + a.name + "'");
    CarriedArray c;
    c.name = a.name;
    c.element_size = a.element_size;
    if (spec->elements_per_particle == 0) {  // a world word
      c.bytes = a.bytes;
    } else {
      c.bytes = kept_bytes(a.bytes, kept, static_cast<size_t>(a.element_size) * spec->elements_per_particle);
      if (spec->rewrite_indices)  // elements naming other particles follow them
        for (size_t e = 0; e < c.bytes.size(); e += a.element_size)
          spec->rewrite_indices(c.bytes.data() + e, new_index_of_old.data());
    }
    out.carried.push_back(std::move(c));
  }
  HostVector<uint32_t> removed = report_.removed_ids;
  removed.insert(removed.end(), ids.begin(), ids.end());
  backend_->import_particles(out);
  report_.removed_ids.swap(removed);  // no throw after the import
}

}  // namespace sph
