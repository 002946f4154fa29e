// SPDX-License-Identifier: MIT
// The CPU backend's particles: creation, appends, truncation, copies out, checkpoints (the twin
// of cuda/cuda_backend.cu).
#include <algorithm>
#include <cstring>
#include <memory>
#include <utility>

#include "cpu_backend.h"
#include "cpu_backend_impl.h"

namespace sph {

namespace {

// Which per-particle inputs a world's force terms read (forces.h), so only those columns exist.
template <class... Terms>
bool reads_neighbor_counts(ForceTerms<Terms...>) {
  return TermList<Terms...>::kReadsNeighborCounts;
}
template <class... Terms>
bool reads_colour_normals(ForceTerms<Terms...>) {
  return TermList<Terms...>::kReadsColourNormals;
}

}  // namespace

CpuBackend::CpuBackend(const WorldConfig& config, unsigned workers, const TaskSystem& tasks)
    : config_(config),
      workers_(workers == 0 ? 1u : workers, tasks),
      grid_(config.kernel_radius, max_particles_per_cell(config.particle_spacing, config.kernel_radius)),
      simd_(best_simd_passes()),
      columns_(with_force_terms(config.selection(), [](auto terms) { return reads_neighbor_counts(terms); }),
               with_force_terms(config.selection(), [](auto terms) { return reads_colour_normals(terms); })),
      method_arrays_(method_particle_arrays(config)) {
  using Role = ParticleArrayRole;
  const auto array = [](const char* name, uint32_t size, Role role) {
    return ParticleArraySpec{name, size, role, 1, nullptr, nullptr};
  };
  position_ = store_.add_typed<Float4>(array(kArrayPosition, sizeof(Float4), Role::Carried));
  velocity_ = store_.add_typed<Float4>(array(kArrayVelocity, sizeof(Float4), Role::Carried));
  id_ = store_.add_typed<uint32_t>(array(kArrayId, sizeof(uint32_t), Role::Carried));
  density_ = store_.add_typed<float>(array(kArrayDensity, sizeof(float), Role::Carried));
  // The statistics read the last density pass's counts after a sink's compaction: they follow it.
  neighbors_ = store_.add_typed<uint32_t>(array(kArrayNeighborCount, sizeof(uint32_t), Role::Sorted));
  next_position_ = store_.add_typed<Float4>(array("next_position", sizeof(Float4), Role::Scratch));
  next_velocity_ = store_.add_typed<Float4>(array("next_velocity", sizeof(Float4), Role::Scratch));
  // Only a world that uses a method pays for its arrays.
  for (const ParticleArraySpec& spec : method_arrays_) store_.add(spec);
  rk4_start_ = store_.find_typed<ParticleState>(kArrayRk4Start);
  rk4_sum_ = store_.find_typed<Rk4Accumulator>(kArrayRk4Sum);
  density_factor_ = store_.find_typed<float>(kArrayDensityFactor);
  normalized_ = store_.find_typed<float>(kArrayNormalizedDensity);
  normals_ = store_.find_typed<Float4>(kArrayColourNormal);
  springs_ = store_.find_typed<SpringList>(kArraySprings);
  link_from_ = store_.find_typed<uint32_t>(kArraySpringLinkFrom);
  spring_candidates_ = store_.find_typed<uint32_t>(kArraySpringCandidates);
  spring_acceleration_ = store_.find_typed<Float4>(kArraySpringAcceleration);
  dfsph_pressure_ = store_.find_typed<float>(kArrayDfsphPressure);
  dfsph_divergence_ = store_.find_typed<float>(kArrayDfsphDivergencePressure);
  dfsph_factor_ = store_.find_typed<float>(kArrayDfsphFactor);
  dfsph_residual_ = store_.find_typed<float>(kArrayDfsphResidual);
  dfsph_contact_ = store_.find_typed<Float4>(kArrayDfsphContact);
  clamp_impulse_ = store_.find_typed<Float4>(kArrayDfsphContactImpulse);
  cg_value_ = store_.find_typed<float>(kArrayDfsphCgValue);
  cg_change_ = store_.find_typed<float>(kArrayDfsphCgChange);
  cg_velocity_step_ = store_.find_typed<Float4>(kArrayDfsphCgVelocityStep);
  cg_state_ = store_.find_typed<uint8_t>(kArrayDfsphCgState);
  boundary_ = store_.find_typed<Float4>(kArrayBoundaryGradient);
  user_attribute_ = store_.find_typed<uint32_t>(kArrayUserAttribute);
}

void CpuBackend::append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id,
                        uint32_t user_attribute) {
  const uint32_t total = count_ + n;
  // New elements of the methods' arrays take their initial values (a fresh density factor, an
  // empty spring list). std::bad_alloc leaves count_ unchanged; the C layer maps it.
  store_.resize(total);
  Float4* position = position_.data();
  Float4* velocity = velocity_.data();
  uint64_t* sort_key = rank_ ? rank_->sort_keys() : nullptr;
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t i = count_ + k;
    const Vec3 v = velocities ? velocities[k] : Vec3{0.0f, 0.0f, 0.0f};
    position[i] = make_float4_record(positions[k], 0.0f);
    velocity[i] = make_float4_record(v, 1.0f / config_.rest_density);
    id_[i] = first_id + k;
    density_[i] = config_.rest_density;
    neighbors_[i] = 0;
    if (user_attribute_) user_attribute_[i] = user_attribute;
    if (sort_key) sort_key[i] = kAppendedSortKey | (first_id + k);
  }
  count_ = total;
  max_speed_valid_ = false;
  if (link_from_ && n > 0 && first_id < link_from_[0])
    link_from_[0] = first_id;  // they link at their first substep
}

void CpuBackend::truncate(uint32_t count) {
  if (count > count_) throw Error(Status::Internal, "truncate: beyond the particle count");
  count_ = count;
  store_.resize(count_);
  max_speed_valid_ = false;
}

void CpuBackend::copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                                size_t stride) const {
  unsigned char* out = static_cast<unsigned char*>(dst);
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t i = first + k;
    unsigned char* p = out + static_cast<size_t>(k) * stride;
    switch (kind) {
      case AttributeKind::Position: {
        const float v[3] = {position_[i].x, position_[i].y, position_[i].z};
        std::memcpy(p, v, sizeof v);
        break;
      }
      case AttributeKind::Velocity: {
        const float v[3] = {velocity_[i].x, velocity_[i].y, velocity_[i].z};
        std::memcpy(p, v, sizeof v);
        break;
      }
      case AttributeKind::Density:
        std::memcpy(p, &density_[i], sizeof(float));
        break;
      case AttributeKind::Pressure:
        std::memcpy(p, &position_[i].w, sizeof(float));
        break;
      case AttributeKind::Id:
        std::memcpy(p, &id_[i], sizeof(uint32_t));
        break;
      case AttributeKind::User:
        std::memcpy(p, &user_attribute_[i], sizeof(uint32_t));
        break;
    }
  }
}

ParticleSnapshot CpuBackend::export_particles() const {
  ParticleSnapshot s;
  s.position.assign(position_.data(), position_.data() + count_);
  s.velocity.assign(velocity_.data(), velocity_.data() + count_);
  s.id.assign(id_.data(), id_.data() + count_);
  s.density.assign(density_.data(), density_.data() + count_);
  // The lazily computed max speed is a pure function of the velocities: taking it now gives
  // the value the next frame would compute.
  s.max_speed = max_speed_valid_ ? max_speed_ : compute_max_speed();
  s.max_acceleration = max_acceleration_;
  for (const ParticleArraySpec& spec : method_arrays_) {
    if (spec.role != ParticleArrayRole::Carried) continue;
    const CpuParticleArray& a = *store_.find(spec.name);
    CarriedArray c;
    c.name = spec.name;
    c.element_size = spec.element_size;
    c.bytes.assign(a.bytes.begin(), a.bytes.begin() + a.elements(count_) * spec.element_size);
    s.carried.push_back(std::move(c));
  }
  // A distributed rank's sort keys (its checkpoint carries them: they order the next sort).
  if (rank_) {
    const uint64_t* keys = rank_->sort_keys();
    s.set_carried(kArrayDistributedSortKey, HostVector<uint64_t>(keys, keys + count_));
  }
  return s;
}

void CpuBackend::import_particles(const ParticleSnapshot& s) {
  const uint32_t n = static_cast<uint32_t>(s.id.size());
  if (n > config_.capacity || s.position.size() != n || s.velocity.size() != n || s.density.size() != n)
    throw Error(Status::Internal, "import_particles: inconsistent snapshot");
  // A distributed rank's sort keys follow its particles: a snapshot that drops or reorders them
  // (sph_world_remove_particles) would leave them behind, unless it carries them (a rank's
  // checkpoint, into a fresh backend).
  std::vector<ParticleArraySpec> carried_specs = method_arrays_;
  HostVector<uint64_t> keys;
  if (rank_) {
    keys = s.carried_as<uint64_t>(kArrayDistributedSortKey);
    if (n != count_ && !(count_ == 0 && keys.size() == n))
      throw Error(Status::Unsupported,
                  "world: removing or restoring particles does not work in a distributed world yet "
                  "(docs/distributed.md)");
    carried_specs.push_back(ParticleArraySpec{kArrayDistributedSortKey, sizeof(uint64_t),
                                              ParticleArrayRole::Carried, 1, nullptr, nullptr});
  }
  check_carried_arrays(s, carried_specs, n);
  // Copies first (they may throw), then the store, so a failure leaves the state as it was.
  HostVector<std::pair<CpuParticleArray*, HostVector<unsigned char>>> carried;
  for (const ParticleArraySpec& spec : method_arrays_)
    if (spec.role == ParticleArrayRole::Carried)
      carried.emplace_back(store_.find(spec.name), carried_bytes(s, spec, n));
  store_.resize(n);
  std::copy(s.position.begin(), s.position.end(), position_.data());
  std::copy(s.velocity.begin(), s.velocity.end(), velocity_.data());
  std::copy(s.id.begin(), s.id.end(), id_.data());
  std::copy(s.density.begin(), s.density.end(), density_.data());
  std::fill(neighbors_.data(), neighbors_.data() + n, 0u);
  for (auto& c : carried) c.first->bytes.swap(c.second);
  if (rank_ && keys.size() == n) std::copy(keys.begin(), keys.end(), rank_->sort_keys());
  count_ = n;
  max_speed_ = s.max_speed;
  max_speed_valid_ = true;
  max_acceleration_ = s.max_acceleration;
}

std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count,
                                          const TaskSystem& tasks) {
  return std::make_unique<CpuBackend>(config, worker_count, tasks);
}

}  // namespace sph
