// The CPU backend's particles: creation, appends, truncation, copies out, checkpoints (the twin
// of cuda/cuda_backend.cu).
#include <cstring>
#include <memory>

#include "../core/grid_layout.h"
#include "../physics/density_normalization.h"
#include "cpu_backend.h"
#include "cpu_backend_impl.h"

namespace sph {

CpuBackend::CpuBackend(const WorldConfig& config, unsigned workers)
    : config_(config),
      workers_(workers == 0 ? 1u : workers),
      grid_(make_grid_shape(config.kernel_radius, config.capacity)),
      position_(store_.add<Float4>()),  // w: pressure after the density pass
      velocity_(store_.add<Float4>()),  // w: 1 / density after the density pass
      id_(store_.add<uint32_t>()),
      density_(store_.add<float>()),
      neighbors_(store_.add<uint32_t>()) {
  if (config.integrator == Integrator::Rk4) {
    // Only an RK4 world pays for the start state and the slope accumulators.
    rk4_start_ = &store_.add<ParticleState>();
    rk4_sum_ = &store_.add<Rk4Accumulator>();
  }
  // Only a world with springs pays for the spring lists.
  if (config.features & kFeatureSprings) springs_ = &store_.add_array(std::make_unique<HostSpringArray>());
  // Normalised density carries a per-particle factor (density_normalization.h): sorted, rolled
  // back and checkpointed with the particles; allocated only when the feature is on.
  if (config.features & kFeatureNormalizedDensity) density_factor_ = &store_.add<float>();
}

void CpuBackend::append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id) {
  const uint32_t total = count_ + n;
  store_.resize(total);  // std::bad_alloc leaves count_ unchanged; the C layer maps it
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t i = count_ + k;
    const Vec3 v = velocities ? velocities[k] : Vec3{0.0f, 0.0f, 0.0f};
    position_.data[i] = make_float4_record(positions[k], 0.0f);
    velocity_.data[i] = make_float4_record(v, 1.0f / config_.rest_density);
    id_.data[i] = first_id + k;
    density_.data[i] = config_.rest_density;
    neighbors_.data[i] = 0;
    if (density_factor_) density_factor_->data[i] = fresh_density_factor();
  }
  count_ = total;
  max_speed_valid_ = false;
  if (springs_ && n > 0 && first_id < link_from_) link_from_ = first_id;  // they link at their first substep
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
        const float v[3] = {position_.data[i].x, position_.data[i].y, position_.data[i].z};
        std::memcpy(p, v, sizeof v);
        break;
      }
      case AttributeKind::Velocity: {
        const float v[3] = {velocity_.data[i].x, velocity_.data[i].y, velocity_.data[i].z};
        std::memcpy(p, v, sizeof v);
        break;
      }
      case AttributeKind::Density:
        std::memcpy(p, &density_.data[i], sizeof(float));
        break;
      case AttributeKind::Pressure:
        std::memcpy(p, &position_.data[i].w, sizeof(float));
        break;
      case AttributeKind::Id:
        std::memcpy(p, &id_.data[i], sizeof(uint32_t));
        break;
    }
  }
}

ParticleSnapshot CpuBackend::export_particles() const {
  ParticleSnapshot s;
  s.position.assign(position_.data.begin(), position_.data.begin() + count_);
  s.velocity.assign(velocity_.data.begin(), velocity_.data.begin() + count_);
  s.id.assign(id_.data.begin(), id_.data.begin() + count_);
  s.density.assign(density_.data.begin(), density_.data.begin() + count_);
  if (density_factor_)
    s.density_factor.assign(density_factor_->data.begin(), density_factor_->data.begin() + count_);
  // The lazily computed max speed is a pure function of the velocities: taking it now gives
  // the value the next frame would compute.
  s.max_speed = max_speed_valid_ ? max_speed_ : compute_max_speed();
  s.max_acceleration = max_acceleration_;
  if (springs_) {
    s.springs.assign(springs_->data.begin(), springs_->data.begin() + count_);
    s.link_from = link_from_;
  }
  return s;
}

void CpuBackend::import_particles(const ParticleSnapshot& s) {
  const uint32_t n = static_cast<uint32_t>(s.id.size());
  if (n > config_.capacity || s.position.size() != n || s.velocity.size() != n || s.density.size() != n)
    throw Error(Status::Internal, "import_particles: inconsistent snapshot");
  if (springs_ ? s.springs.size() != n : !s.springs.empty())
    throw Error(Status::Internal, "import_particles: spring lists do not match the particles");
  std::vector<SpringList> springs(s.springs);
  // Copies first (they may throw), then swaps, so a failure leaves the state as it was.
  std::vector<Float4> position(s.position), velocity(s.velocity);
  std::vector<uint32_t> id(s.id), neighbors(n, 0u);
  std::vector<float> density(s.density);
  std::vector<float> factor;
  if (density_factor_) {
    // A snapshot without factors (a checkpoint written before they existed) starts every
    // particle fresh, as if it had just been spawned.
    if (!s.density_factor.empty() && s.density_factor.size() != n)
      throw Error(Status::Internal, "import_particles: inconsistent snapshot");
    factor = s.density_factor.empty() ? std::vector<float>(n, fresh_density_factor()) : s.density_factor;
  }
  store_.resize(n);
  position_.data.swap(position);
  velocity_.data.swap(velocity);
  id_.data.swap(id);
  density_.data.swap(density);
  neighbors_.data.swap(neighbors);
  if (springs_) {
    springs_->data.swap(springs);
    link_from_ = s.link_from;
  }
  if (density_factor_) density_factor_->data.swap(factor);
  count_ = n;
  max_speed_ = s.max_speed;
  max_speed_valid_ = true;
  max_acceleration_ = s.max_acceleration;
}

std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count) {
  return std::make_unique<CpuBackend>(config, worker_count);
}

}  // namespace sph
