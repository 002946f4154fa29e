// SPDX-License-Identifier: MIT
// The CUDA backend's particle count and capacity: appending (spawns, fills, sources), dropping an
// emission again after a failed step, growing the storage (all-or-nothing), and the step inputs
// saved around an emission.
#include <memory>
#include <utility>
#include <vector>

#include "../src/core/crowded_cell.h"
#include "../src/core/grid_layout.h"
#include "cuda_backend_impl.h"
#include "device_springs.h"

namespace sph {

void CudaBackend::append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id,
                         uint32_t user_attribute) {
  require_alive();
  DeviceGuard guard(device_);
  HostVector<Float4> pos(n), vel(n);
  HostVector<uint32_t> ids(n);
  const HostVector<float> density(n, config_.rest_density);
  // The methods' carried arrays start at their initial values (a fresh density factor, which
  // the first density pass resolves; an empty spring list).
  HostVector<HostVector<unsigned char>> initial;
  for (const auto& m : r_->store->method_arrays())
    if (m->spec.role == ParticleArrayRole::Carried && m->spec.elements_per_particle != 0)
      initial.push_back(carried_bytes(ParticleSnapshot{}, m->spec, n));
  // The user attribute starts at the caller's value instead.
  {
    size_t k = 0;
    for (const auto& m : r_->store->method_arrays()) {
      if (m->spec.role != ParticleArrayRole::Carried || m->spec.elements_per_particle == 0) continue;
      if (std::strcmp(m->spec.name, kArrayUserAttribute) == 0)
        for (uint32_t e = 0; e < n; ++e)
          std::memcpy(initial[k].data() + sizeof(uint32_t) * e, &user_attribute, sizeof(uint32_t));
      ++k;
    }
  }
  for (uint32_t k = 0; k < n; ++k) {
    const Vec3 v = velocities ? velocities[k] : Vec3{0.0f, 0.0f, 0.0f};
    pos[k] = make_float4_record(positions[k], 0.0f);
    vel[k] = make_float4_record(v, 1.0f / config_.rest_density);
    ids[k] = first_id + k;
  }
  guarded([&] {
    const ParticleArrays& a = r_->store->arrays();
    cudaStream_t s = r_->stream;
    cuda_check(
        cudaMemcpyAsync(a.position + count_, pos.data(), sizeof(Float4) * n, cudaMemcpyHostToDevice, s),
        "copy of new positions");
    cuda_check(
        cudaMemcpyAsync(a.velocity + count_, vel.data(), sizeof(Float4) * n, cudaMemcpyHostToDevice, s),
        "copy of new velocities");
    cuda_check(cudaMemcpyAsync(a.id + count_, ids.data(), sizeof(uint32_t) * n, cudaMemcpyHostToDevice, s),
               "copy of new ids");
    cuda_check(
        cudaMemcpyAsync(a.density + count_, density.data(), sizeof(float) * n, cudaMemcpyHostToDevice, s),
        "copy of new densities");
    size_t k = 0;
    for (const auto& m : r_->store->method_arrays()) {
      if (m->spec.role != ParticleArrayRole::Carried || m->spec.elements_per_particle == 0) continue;
      if (n > 0)
        cuda_check(cudaMemcpyAsync(m->side[0].get() + m->bytes_for(count_), initial[k].data(),
                                   m->bytes_for(n), cudaMemcpyHostToDevice, s),
                   m->spec.name);
      ++k;
    }
    // New particles have no springs yet; they make them at their first substep.
    if (a.springs && n > 0) enqueue_springs_appended(a, first_id, s);
    // A distributed rank's new particles sort after every sorted one, in id order (cuda_halo.cu).
    HostVector<uint64_t> keys;
    if (r_->halo && n > 0) {
      keys.resize(n);
      for (uint32_t k = 0; k < n; ++k) keys[k] = kAppendedSortKey | (first_id + k);
      uint64_t* key = static_cast<uint64_t*>(r_->store->find(kArrayDistributedSortKey));
      cuda_check(cudaMemcpyAsync(key + count_, keys.data(), sizeof(uint64_t) * n, cudaMemcpyHostToDevice, s),
                 "copy of new sort keys");
    }
    enqueue_recompute_max_speed(a.velocity, count_ + n, r_->state.get(), s);
    cuda_check(cudaStreamSynchronize(s), "append");
  });
  count_ += n;
  ++epoch_;
}

// Drops particles [count, particle_count()) (an emission undone after a failed step).
void CudaBackend::truncate(uint32_t count) {
  require_alive();
  if (count > count_) throw Error(Status::Internal, "truncate: beyond the particle count");
  if (count == count_) return;
  DeviceGuard guard(device_);
  guarded([&] {
    enqueue_recompute_max_speed(r_->store->arrays().velocity, count, r_->state.get(), r_->stream);
    cuda_check(cudaStreamSynchronize(r_->stream), "truncate");
  });
  count_ = count;
  ++epoch_;
}

void CudaBackend::reserve(uint32_t capacity, const GrowthNeeds& needs) {
  require_alive();
  if (capacity <= config_.capacity) return;
  DeviceGuard guard(device_);
  guarded([&] {
    std::vector<ParticleArraySpec> specs;
    for (const auto& m : r_->store->method_arrays()) specs.push_back(m->spec);
    auto store = std::make_unique<DeviceParticleStore>(capacity, specs);
    // The grid is sized from the capacity, as a world created at this capacity sizes it, so a
    // grown world sorts (and computes) exactly as that world would.
    auto grid = std::make_unique<DeviceNeighborGrid>(
        make_grid_shape(config_.kernel_radius, capacity), capacity,
        max_particles_per_cell(config_.particle_spacing, config_.kernel_radius), store->sort_scratch(),
        store->arrays().sorted_position, sizeof(Float4) * static_cast<size_t>(capacity), r_->stream);
    auto statistics = std::make_unique<FrameStatistics>(capacity);
    DeviceArray<double> partials;
    if (options_.dfsph) partials.allocate(dfsph_partial_count(capacity), "DFSPH solve sums");
    // The frame's capacity-sized buffers grow with the storage, inside the all-or-nothing
    // growth: the frame that grew the world then allocates none of them, so it cannot fail with
    // the world grown (gpu_check_allocation_faults).
    DeviceSinkCompactor sinks;
    if (needs.sinks) sinks.reserve(capacity, *store);
    DeviceColliderLoads loads;
    if (needs.load_colliders != 0) loads.reserve(needs.load_colliders, capacity);
    std::unique_ptr<DeviceHalo> halo;
    if (r_->halo) halo = std::make_unique<DeviceHalo>(capacity, ranks_->size(), r_->stream);
    std::unique_ptr<DeviceHaloSprings> halo_springs;
    if (r_->halo_springs) halo_springs = std::make_unique<DeviceHaloSprings>(capacity, r_->stream);
    store->enqueue_copy_from(*r_->store, count_, r_->stream);
    cuda_check(cudaStreamSynchronize(r_->stream), "growth of the particle storage");
    // Nothing below throws: the new buffers replace the old ones (freed at the end of scope).
    r_->graph.reset();
    r_->grid.swap(grid);
    r_->store.swap(store);
    r_->statistics.swap(statistics);
    std::swap(r_->solve_partials, partials);
    if (needs.sinks) std::swap(r_->sinks, sinks);
    if (needs.load_colliders != 0) std::swap(r_->loads, loads);
    if (halo) r_->halo.swap(halo);
    if (halo_springs) r_->halo_springs.swap(halo_springs);
  });
  config_.capacity = capacity;
  ++epoch_;
}

void CudaBackend::save_step_inputs() {
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] { copy_step_inputs(/*save=*/true); });
}

void CudaBackend::restore_step_inputs() {
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] {
    copy_step_inputs(/*save=*/false);
    cuda_check(cudaStreamSynchronize(r_->stream), "restore of the step inputs");
  });
}

void CudaBackend::copy_step_inputs(bool save) {
  FrameState* s = r_->state.get();
  float* const carried[2] = {&s->max_speed, &s->max_acceleration};
  float* const saved[2] = {&s->emission_saved_max_speed, &s->emission_saved_max_acceleration};
  for (int k = 0; k < 2; ++k)
    cuda_check(cudaMemcpyAsync(save ? saved[k] : carried[k], save ? carried[k] : saved[k], sizeof(float),
                               cudaMemcpyDeviceToDevice, r_->stream),
               "copy of the step inputs");
  // The springs' lowest waiting id: an emission lowers it, a failed step must not leave it there.
  uint32_t* const link_from = r_->store->arrays().link_from;
  if (link_from)
    cuda_check(cudaMemcpyAsync(save ? &s->emission_saved_link_from : link_from,
                               save ? link_from : &s->emission_saved_link_from, sizeof(uint32_t),
                               cudaMemcpyDeviceToDevice, r_->stream),
               "copy of the springs' link state");
}

}  // namespace sph
