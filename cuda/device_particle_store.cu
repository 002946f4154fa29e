#include "device_particle_store.h"

namespace sph {

DeviceParticleStore::DeviceParticleStore(uint32_t capacity, const StoreOptions& options)
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
  if (options.neighbor_counts) neighbor_count_.allocate(n, "neighbour counts");
  if (options.normalized_density) {
    normalized_density_.allocate(n, "normalised densities");
    density_factor_.allocate(n, "density factors");
    snapshot_density_factor_.allocate(n, "snapshot density factors");
  }
  if (options.colour_normals) colour_normal_.allocate(n, "colour-field normals");
  if (options.springs) {
    springs_.allocate(n, "spring lists");
    sorted_springs_.allocate(n, "sorted spring lists");
    snapshot_springs_.allocate(n, "snapshot spring lists");
    spring_inverse_.allocate(n, "spring index map");
    spring_candidates_.allocate(n * kSpringSlots, "spring link candidates");
    spring_acceleration_.allocate(n, "spring accelerations");
    link_from_.allocate(1, "first id waiting for springs");
    snapshot_link_from_.allocate(1, "snapshot first id waiting for springs");
  }
  if (options.rk4) {
    for (int side = 0; side < 2; ++side) {
      rk4_start_[side].allocate(n, "RK4 start states");
      rk4_sum_[side].allocate(n, "RK4 slope sums");
    }
  }
  arrays_.position = position_.get();
  arrays_.velocity = velocity_.get();
  arrays_.id = id_.get();
  arrays_.density = density_.get();
  arrays_.sorted_position = sorted_position_.get();
  arrays_.sorted_velocity = sorted_velocity_.get();
  arrays_.sorted_id = sorted_id_.get();
  arrays_.neighbor_count = neighbor_count_.get();
  arrays_.normalized_density = normalized_density_.get();
  arrays_.density_factor = density_factor_.get();
  arrays_.colour_normal = colour_normal_.get();
  arrays_.springs = springs_.get();
  arrays_.sorted_springs = sorted_springs_.get();
  arrays_.spring_inverse = spring_inverse_.get();
  arrays_.spring_candidates = spring_candidates_.get();
  arrays_.spring_acceleration = spring_acceleration_.get();
  arrays_.link_from = link_from_.get();
  for (int side = 0; side < 2; ++side) {
    arrays_.rk4_start[side] = rk4_start_[side].get();
    arrays_.rk4_sum[side] = rk4_sum_[side].get();
  }
}

SortScratch DeviceParticleStore::sort_scratch() const {
  static_assert(sizeof(Float4) == 4 * sizeof(uint32_t), "four uint32 arrays fit in one Float4 array");
  uint32_t* base = reinterpret_cast<uint32_t*>(sorted_velocity_.get());
  const size_t n = capacity_;
  return SortScratch{{base, base + n}, {base + 2 * n, base + 3 * n}};
}

namespace {

template <class T>
void copy_async(T* dst, const T* src, uint32_t n, cudaStream_t stream, const char* what) {
  if (n == 0) return;
  cuda_check(cudaMemcpyAsync(dst, src, sizeof(T) * n, cudaMemcpyDeviceToDevice, stream), what);
}

}  // namespace

void DeviceParticleStore::enqueue_snapshot(uint32_t n, cudaStream_t stream) const {
  copy_async(snapshot_position_.get(), position_.get(), n, stream, "snapshot of positions");
  copy_async(snapshot_velocity_.get(), velocity_.get(), n, stream, "snapshot of velocities");
  copy_async(snapshot_id_.get(), id_.get(), n, stream, "snapshot of ids");
  copy_async(snapshot_density_.get(), density_.get(), n, stream, "snapshot of densities");
  if (springs_.get()) {
    copy_async(snapshot_springs_.get(), springs_.get(), n, stream, "snapshot of spring lists");
    copy_async(snapshot_link_from_.get(), link_from_.get(), 1, stream, "snapshot of the spring link state");
  }
  if (density_factor_.get())
    copy_async(snapshot_density_factor_.get(), density_factor_.get(), n, stream,
               "snapshot of density factors");
}

void DeviceParticleStore::enqueue_restore(uint32_t n, cudaStream_t stream) const {
  copy_async(position_.get(), snapshot_position_.get(), n, stream, "restore of positions");
  copy_async(velocity_.get(), snapshot_velocity_.get(), n, stream, "restore of velocities");
  copy_async(id_.get(), snapshot_id_.get(), n, stream, "restore of ids");
  copy_async(density_.get(), snapshot_density_.get(), n, stream, "restore of densities");
  if (springs_.get()) {
    copy_async(springs_.get(), snapshot_springs_.get(), n, stream, "restore of spring lists");
    copy_async(link_from_.get(), snapshot_link_from_.get(), 1, stream, "restore of the spring link state");
  }
  if (density_factor_.get())
    copy_async(density_factor_.get(), snapshot_density_factor_.get(), n, stream,
               "restore of density factors");
}

void DeviceParticleStore::enqueue_reset_link_state(cudaStream_t stream) const {
  if (!link_from_.get()) return;
  // No particle waits yet; the snapshot word too, so a rollback before any frame keeps it.
  cuda_check(cudaMemsetAsync(link_from_.get(), 0xff, sizeof(uint32_t), stream), "spring link state reset");
  cuda_check(cudaMemsetAsync(snapshot_link_from_.get(), 0xff, sizeof(uint32_t), stream),
             "spring link state reset");
}

uint64_t DeviceParticleStore::bytes() const {
  uint64_t total = position_.bytes() + velocity_.bytes() + id_.bytes() + density_.bytes() +
                   sorted_position_.bytes() + sorted_velocity_.bytes() + sorted_id_.bytes() +
                   snapshot_position_.bytes() + snapshot_velocity_.bytes() + snapshot_id_.bytes() +
                   snapshot_density_.bytes();
  for (int side = 0; side < 2; ++side) total += rk4_start_[side].bytes() + rk4_sum_[side].bytes();
  total += neighbor_count_.bytes() + normalized_density_.bytes() + colour_normal_.bytes();
  total += springs_.bytes() + sorted_springs_.bytes() + snapshot_springs_.bytes() + spring_inverse_.bytes() +
           spring_candidates_.bytes() + spring_acceleration_.bytes() + link_from_.bytes() +
           snapshot_link_from_.bytes();
  total += density_factor_.bytes() + snapshot_density_factor_.bytes();
  return total;
}

}  // namespace sph
