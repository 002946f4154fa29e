// SPDX-License-Identifier: MIT
#include "device_particle_store.h"

#include <cstring>

#include "../src/physics/collider_loads.h"
#include "device_springs.h"

namespace sph {

DeviceParticleStore::DeviceParticleStore(uint32_t capacity,
                                         const std::vector<ParticleArraySpec>& method_arrays)
    : capacity_(capacity) {
  const size_t n = capacity;
  position_.allocate(n, "positions");
  velocity_.allocate(n, "velocities");
  id_.allocate(n, "ids");
  density_.allocate(n, "densities");
  sorted_position_.allocate(n, "sorted positions");
  sorted_velocity_.allocate(n, "sorted velocities");
  sorted_id_.allocate(n, "sorted ids");
  snapshot_position_.allocate(n, "snapshot positions");
  snapshot_velocity_.allocate(n, "snapshot velocities");
  snapshot_id_.allocate(n, "snapshot ids");
  snapshot_density_.allocate(n, "snapshot densities");
  for (const ParticleArraySpec& spec : method_arrays) {
    auto a = std::make_unique<DeviceMethodArray>();
    a->spec = spec;
    a->elements =
        spec.elements_per_particle == 0 ? 1u : static_cast<uint64_t>(n) * spec.elements_per_particle;
    const size_t bytes = a->elements * spec.element_size;
    a->side[0].allocate(bytes, spec.name);
    if (spec.role == ParticleArrayRole::Sorted) a->side[1].allocate(bytes, spec.name);
    if (spec.role == ParticleArrayRole::Carried) a->snapshot.allocate(a->bytes_for(capacity), spec.name);
    methods_.push_back(std::move(a));
  }
  arrays_.position = position_.get();
  arrays_.velocity = velocity_.get();
  arrays_.id = id_.get();
  arrays_.density = density_.get();
  arrays_.sorted_position = sorted_position_.get();
  arrays_.sorted_velocity = sorted_velocity_.get();
  arrays_.sorted_id = sorted_id_.get();
  arrays_.neighbor_count = static_cast<uint32_t*>(find(kArrayNeighborCount));
  arrays_.normalized_density = static_cast<float*>(find(kArrayNormalizedDensity));
  arrays_.density_factor = static_cast<float*>(find(kArrayDensityFactor));
  arrays_.colour_normal = static_cast<Float4*>(find(kArrayColourNormal));
  arrays_.springs = static_cast<SpringList*>(find(kArraySprings));
  arrays_.sorted_springs = static_cast<SpringList*>(find(kArraySortedSprings));
  arrays_.spring_inverse = static_cast<uint32_t*>(find(kArraySpringInverse));
  arrays_.spring_candidates = static_cast<uint32_t*>(find(kArraySpringCandidates));
  arrays_.spring_acceleration = static_cast<Float4*>(find(kArraySpringAcceleration));
  arrays_.link_from = static_cast<uint32_t*>(find(kArraySpringLinkFrom));
  arrays_.dfsph_pressure = static_cast<float*>(find(kArrayDfsphPressure));
  arrays_.dfsph_divergence = static_cast<float*>(find(kArrayDfsphDivergencePressure));
  arrays_.dfsph_factor = static_cast<float*>(find(kArrayDfsphFactor));
  arrays_.dfsph_step = static_cast<float*>(find(kArrayDfsphStep));
  arrays_.dfsph_warm_pressure = static_cast<float*>(find(kArrayDfsphWarmPressure));
  arrays_.dfsph_contact = static_cast<Float4*>(find(kArrayDfsphContact));
  arrays_.dfsph_contact_impulse = static_cast<Float4*>(find(kArrayDfsphContactImpulse));
  arrays_.dfsph_residual = static_cast<float*>(find(kArrayDfsphResidual));
  arrays_.dfsph_neighbor_mask = static_cast<uint32_t*>(find(kArrayDfsphNeighborMask));
  arrays_.dfsph_neighbor_list = static_cast<uint32_t*>(find(kArrayDfsphNeighborList));
  arrays_.dfsph_list_stride = capacity;
  arrays_.dfsph_cg_value = static_cast<float*>(find(kArrayDfsphCgValue));
  arrays_.dfsph_cg_change = static_cast<float*>(find(kArrayDfsphCgChange));
  arrays_.dfsph_cg_velocity_step = static_cast<Float4*>(find(kArrayDfsphCgVelocityStep));
  arrays_.dfsph_cg_state = static_cast<uint8_t*>(find(kArrayDfsphCgState));
  arrays_.boundary_gradient = static_cast<Float4*>(find(kArrayBoundaryGradient));
  arrays_.user_attribute = static_cast<uint32_t*>(find(kArrayUserAttribute));
  arrays_.sorted_user_attribute = static_cast<uint32_t*>(find(kArraySortedUserAttribute));
  arrays_.halo_ghost = static_cast<uint32_t*>(find(kArrayHaloGhost));
  for (int side = 0; side < 2; ++side) {
    arrays_.rk4_start[side] = static_cast<ParticleState*>(find(kArrayRk4Start, side));
    arrays_.rk4_sum[side] = static_cast<Rk4Accumulator*>(find(kArrayRk4Sum, side));
  }
}

void* DeviceParticleStore::find(const char* name, int side) const {
  for (const auto& a : methods_)
    if (std::strcmp(a->spec.name, name) == 0) return a->side[side].get();
  return nullptr;
}

SortScratch DeviceParticleStore::sort_scratch() const {
  static_assert(sizeof(Float4) == 4 * sizeof(uint32_t), "four uint32 arrays fit in one Float4 array");
  uint32_t* base = reinterpret_cast<uint32_t*>(sorted_velocity_.get());
  const size_t n = capacity_;
  return SortScratch{{base, base + n}, {base + 2 * n, base + 3 * n}};
}

namespace {

template <class T>
void copy_async(T* dst, const T* src, uint64_t n, cudaStream_t stream, const char* what) {
  if (n == 0) return;
  cuda_check(cudaMemcpyAsync(dst, src, sizeof(T) * n, cudaMemcpyDeviceToDevice, stream), what);
}

}  // namespace

void DeviceParticleStore::enqueue_snapshot(uint32_t n, cudaStream_t stream) const {
  copy_async(snapshot_position_.get(), position_.get(), n, stream, "snapshot of positions");
  copy_async(snapshot_velocity_.get(), velocity_.get(), n, stream, "snapshot of velocities");
  copy_async(snapshot_id_.get(), id_.get(), n, stream, "snapshot of ids");
  copy_async(snapshot_density_.get(), density_.get(), n, stream, "snapshot of densities");
  for (const auto& a : methods_)
    if (a->spec.role == ParticleArrayRole::Carried)
      copy_async(a->snapshot.get(), a->side[0].get(), a->bytes_for(n), stream, a->spec.name);
}

void DeviceParticleStore::enqueue_restore(uint32_t n, cudaStream_t stream) const {
  copy_async(position_.get(), snapshot_position_.get(), n, stream, "restore of positions");
  copy_async(velocity_.get(), snapshot_velocity_.get(), n, stream, "restore of velocities");
  copy_async(id_.get(), snapshot_id_.get(), n, stream, "restore of ids");
  copy_async(density_.get(), snapshot_density_.get(), n, stream, "restore of densities");
  for (const auto& a : methods_)
    if (a->spec.role == ParticleArrayRole::Carried)
      copy_async(a->side[0].get(), a->snapshot.get(), a->bytes_for(n), stream, a->spec.name);
}

void DeviceParticleStore::enqueue_initial_world_words(cudaStream_t stream) const {
  for (const auto& a : methods_) {
    if (a->spec.elements_per_particle != 0 || !a->spec.initial) continue;
    // The snapshot too, so a rollback before any frame keeps the value.
    for (unsigned char* dst : {a->side[0].get(), a->snapshot.get()})
      if (dst)
        cuda_check(
            cudaMemcpyAsync(dst, a->spec.initial, a->spec.element_size, cudaMemcpyHostToDevice, stream),
            a->spec.name);
  }
}

void DeviceParticleStore::enqueue_copy_from(const DeviceParticleStore& from, uint32_t n,
                                            cudaStream_t stream) const {
  if (n > capacity_ || n > from.capacity_ || methods_.size() != from.methods_.size())
    throw Error(Status::Internal, "copy of the particle store: the stores do not match");
  copy_async(position_.get(), from.position_.get(), n, stream, "growth: positions");
  copy_async(velocity_.get(), from.velocity_.get(), n, stream, "growth: velocities");
  copy_async(id_.get(), from.id_.get(), n, stream, "growth: ids");
  copy_async(density_.get(), from.density_.get(), n, stream, "growth: densities");
  for (size_t k = 0; k < methods_.size(); ++k) {
    const DeviceMethodArray& to = *methods_[k];
    const DeviceMethodArray& old = *from.methods_[k];
    if (to.spec.role != ParticleArrayRole::Carried) continue;
    copy_async(to.side[0].get(), old.side[0].get(), to.bytes_for(n), stream, to.spec.name);
    copy_async(to.snapshot.get(), old.snapshot.get(), to.bytes_for(n), stream, to.spec.name);
  }
}

uint64_t DeviceParticleStore::bytes() const {
  uint64_t total = position_.bytes() + velocity_.bytes() + id_.bytes() + density_.bytes() +
                   sorted_position_.bytes() + sorted_velocity_.bytes() + sorted_id_.bytes() +
                   snapshot_position_.bytes() + snapshot_velocity_.bytes() + snapshot_id_.bytes() +
                   snapshot_density_.bytes();
  for (const auto& a : methods_) total += a->side[0].bytes() + a->side[1].bytes() + a->snapshot.bytes();
  return total;
}

}  // namespace sph
