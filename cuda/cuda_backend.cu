// SPDX-License-Identifier: MIT
// The CUDA backend's particles: creation, appends, truncation, copies out, checkpoints and the
// interop tier of sph_cuda.h (the twin of src/cpu/cpu_backend.cpp; frames are frame_loop.cu).
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../src/core/crowded_cell.h"
#include "../src/core/grid_layout.h"
#include "cuda_backend.h"
#include "cuda_backend_impl.h"
#include "device_springs.h"

namespace sph {
CudaBackend::CudaBackend(const WorldConfig& config, int device, const CudaBackendOptions& options)
    : config_(config), device_(device) {
  DeviceGuard guard(device_);
  auto r = std::make_unique<DeviceResources>();
  cuda_check(cudaStreamCreateWithFlags(&r->stream, cudaStreamNonBlocking), "cudaStreamCreate");
  cuda_check(cudaEventCreate(&r->frame_start), "cudaEventCreate");
  cuda_check(cudaEventCreate(&r->frame_stop), "cudaEventCreate");
  cuda_check(cudaEventCreateWithFlags(&r->order_event, cudaEventDisableTiming), "cudaEventCreate");
  options_.methods = config.selection();
  options_.surface_tension = (config.features & kFeatureSurfaceTension) != 0;
  options_.normalized_density = (config.features & kFeatureNormalizedDensity) != 0;
  options_.density_diffusion = (config.features & kFeatureDensityDiffusion) != 0;
  options_.viscosity = config.viscosity_method;
  options_.springs = (config.features & kFeatureSprings) != 0;
  options_.dfsph = config.solver == Solver::Dfsph;
  options_.boundary_density = (config.features & kFeatureBoundaryDensity) != 0;
  // The methods' arrays (particle_arrays.h), and this backend's working arrays for springs.
  std::vector<ParticleArraySpec> arrays = method_particle_arrays(config);
  if (options_.springs)
    for (const ParticleArraySpec& spec : spring_device_arrays()) arrays.push_back(spec);
  if (config.features & kFeatureUserAttribute)
    arrays.push_back(ParticleArraySpec{kArraySortedUserAttribute, sizeof(uint32_t),
                                       ParticleArrayRole::Scratch, 1, nullptr, nullptr});
  if (options_.dfsph && options.dfsph_masks)
    arrays.push_back(ParticleArraySpec{kArrayDfsphNeighborMask, sizeof(uint32_t), ParticleArrayRole::Scratch,
                                       kNeighborMaskWords, nullptr, nullptr});
  if (options_.dfsph && options.dfsph_masks && options.dfsph_lists)
    arrays.push_back(ParticleArraySpec{kArrayDfsphNeighborList, sizeof(uint32_t), ParticleArrayRole::Scratch,
                                       kNeighborListRows, nullptr, nullptr});
  r->store = std::make_unique<DeviceParticleStore>(config.capacity, arrays);
  // The sorted positions are free while the sort runs: its temporary storage goes there.
  r->grid = std::make_unique<DeviceNeighborGrid>(
      make_grid_shape(config.kernel_radius, config.capacity), config.capacity,
      max_particles_per_cell(config.particle_spacing, config.kernel_radius), r->store->sort_scratch(),
      r->store->arrays().sorted_position, sizeof(Float4) * static_cast<size_t>(config.capacity), r->stream);
  r->statistics = std::make_unique<FrameStatistics>(config.capacity);
  r->state.allocate(1, "frame state");
  if (options_.dfsph) r->solve_partials.allocate(dfsph_partial_count(config.capacity), "DFSPH solve sums");
  cuda_check(cudaMemsetAsync(r->state.get(), 0, sizeof(FrameState), r->stream), "frame state reset");
  r->store->enqueue_initial_world_words(r->stream);
  r->input.allocate(1, "frame input");
  r->state_output.allocate(1, "frame output");
  r->sink_kept.allocate(1, "sink survivor count");
  cuda_check(cudaStreamSynchronize(r->stream), "backend set-up");
  tuning_.density_block = options.density_block;
  tuning_.force_block = options.force_block;
  tuning_.particle_lanes = options.particle_lanes;
  int sms = 0, threads_per_sm = 0;
  cuda_check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device_), "cudaDeviceGetAttribute");
  cuda_check(cudaDeviceGetAttribute(&threads_per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, device_),
             "cudaDeviceGetAttribute");
  tuning_.thread_slots = static_cast<unsigned>(sms) * static_cast<unsigned>(threads_per_sm);
  use_graphs_ = !options.stream_frames;
  r_ = std::move(r);
}

CudaBackend::~CudaBackend() {
  DeviceGuard* guard = nullptr;
  try {
    guard = new DeviceGuard(device_);
  } catch (...) {
  }
  r_.reset();
  delete guard;
}

void CudaBackend::copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                                 size_t stride) const {
  require_alive();
  DeviceGuard guard(device_);
  const ParticleArrays& a = r_->store->arrays();
  unsigned char* out = static_cast<unsigned char*>(dst);
  switch (kind) {
    case AttributeKind::Position:
    case AttributeKind::Velocity:
    case AttributeKind::Pressure: {
      const Float4* src = (kind == AttributeKind::Velocity ? a.velocity : a.position) + first;
      const HostVector<Float4> host = download(src, count);
      for (uint32_t k = 0; k < count; ++k) {
        unsigned char* p = out + static_cast<size_t>(k) * stride;
        if (kind == AttributeKind::Pressure) {
          std::memcpy(p, &host[k].w, sizeof(float));
        } else {
          const float v[3] = {host[k].x, host[k].y, host[k].z};
          std::memcpy(p, v, sizeof v);
        }
      }
      break;
    }
    case AttributeKind::Density:
      scatter(download(a.density + first, count), out, stride);
      break;
    case AttributeKind::Id:
      scatter(download(a.id + first, count), out, stride);
      break;
    case AttributeKind::User:
      scatter(download(a.user_attribute + first, count), out, stride);
      break;
  }
}

// Checkpoints: the state in storage order and the frame state that carries over (max speed,
// max acceleration); everything else in FrameState is reset when a frame begins.
ParticleSnapshot CudaBackend::export_particles() const {
  require_alive();
  DeviceGuard guard(device_);
  const ParticleArrays& a = r_->store->arrays();
  ParticleSnapshot s;
  s.position = download(a.position, count_);
  s.velocity = download(a.velocity, count_);
  s.id = download(a.id, count_);
  s.density = download(a.density, count_);
  const HostVector<FrameState> state = download(static_cast<const FrameState*>(r_->state.get()), 1u);
  s.max_speed = state[0].max_speed;
  s.max_acceleration = state[0].max_acceleration;
  for (const auto& m : r_->store->method_arrays()) {
    if (m->spec.role != ParticleArrayRole::Carried) continue;
    CarriedArray c;
    c.name = m->spec.name;
    c.element_size = m->spec.element_size;
    c.bytes = download(static_cast<const unsigned char*>(m->side[0].get()), m->bytes_for(count_));
    s.carried.push_back(std::move(c));
  }
  return s;
}

void CudaBackend::import_particles(const ParticleSnapshot& s) {
  require_alive();
  const uint32_t n = static_cast<uint32_t>(s.id.size());
  if (n > config_.capacity || s.position.size() != n || s.velocity.size() != n || s.density.size() != n)
    throw Error(Status::Internal, "import_particles: inconsistent snapshot");
  std::vector<ParticleArraySpec> specs;
  for (const auto& m : r_->store->method_arrays()) specs.push_back(m->spec);
  // A distributed rank's sort keys follow its particles: a snapshot that drops or reorders them
  // (sph_world_remove_particles) would leave them behind, unless it carries them (a rank's
  // checkpoint, into a fresh backend).
  if (ranks_ && n != count_ && !(count_ == 0 && s.carried_as<uint64_t>(kArrayDistributedSortKey).size() == n))
    throw Error(Status::Unsupported,
                "world: removing or restoring particles does not work in a distributed world yet "
                "(docs/distributed.md)");
  check_carried_arrays(s, specs, n);
  // A carried array the snapshot lacks (a checkpoint written before the method carried it)
  // starts every particle fresh, as if it had just been spawned.
  HostVector<HostVector<unsigned char>> carried;
  for (const auto& m : r_->store->method_arrays())
    if (m->spec.role == ParticleArrayRole::Carried) carried.push_back(carried_bytes(s, m->spec, n));
  DeviceGuard guard(device_);
  ++epoch_;
  guarded([&] {
    const ParticleArrays& a = r_->store->arrays();
    cudaStream_t st = r_->stream;
    if (n > 0) {
      cuda_check(
          cudaMemcpyAsync(a.position, s.position.data(), sizeof(Float4) * n, cudaMemcpyHostToDevice, st),
          "copy of checkpoint positions");
      cuda_check(
          cudaMemcpyAsync(a.velocity, s.velocity.data(), sizeof(Float4) * n, cudaMemcpyHostToDevice, st),
          "copy of checkpoint velocities");
      cuda_check(cudaMemcpyAsync(a.id, s.id.data(), sizeof(uint32_t) * n, cudaMemcpyHostToDevice, st),
                 "copy of checkpoint ids");
      cuda_check(cudaMemcpyAsync(a.density, s.density.data(), sizeof(float) * n, cudaMemcpyHostToDevice, st),
                 "copy of checkpoint densities");
    }
    size_t k = 0;
    for (const auto& m : r_->store->method_arrays()) {
      if (m->spec.role != ParticleArrayRole::Carried) continue;
      if (!carried[k].empty())
        cuda_check(cudaMemcpyAsync(m->side[0].get(), carried[k].data(), carried[k].size(),
                                   cudaMemcpyHostToDevice, st),
                   m->spec.name);
      ++k;
    }
    FrameState* state = r_->state.get();
    cuda_check(cudaMemcpyAsync(&state->max_speed, &s.max_speed, sizeof(float), cudaMemcpyHostToDevice, st),
               "copy of the checkpoint's max speed");
    cuda_check(cudaMemcpyAsync(&state->max_acceleration, &s.max_acceleration, sizeof(float),
                               cudaMemcpyHostToDevice, st),
               "copy of the checkpoint's max acceleration");
    cuda_check(cudaStreamSynchronize(st), "import of a checkpoint");
  });
  count_ = n;
}

uint64_t CudaBackend::memory_bytes() const {
  return r_->store->bytes() + r_->grid->bytes() + r_->statistics->bytes() + r_->state.bytes() +
         r_->sdf_cache.bytes() + r_->scene_buffer.bytes() + r_->sinks.bytes() + r_->solve_partials.bytes() +
         r_->boundary_maps.bytes() + r_->loads.bytes() + r_->probes.bytes() +
         (r_->halo ? r_->halo->bytes() : 0) + (r_->halo_springs ? r_->halo_springs->bytes() : 0);
}

DeviceAttributeView CudaBackend::device_attribute(AttributeKind kind) const {
  require_alive();
  const ParticleArrays& a = r_->store->arrays();
  DeviceAttributeView v;
  v.count = count_;
  v.epoch = epoch_;
  v.device = device_;
  switch (kind) {
    case AttributeKind::Position:
      v = with(v, reinterpret_cast<uintptr_t>(a.position), sizeof(Float4), 12);
      break;
    case AttributeKind::Velocity:
      v = with(v, reinterpret_cast<uintptr_t>(a.velocity), sizeof(Float4), 12);
      break;
    case AttributeKind::Pressure:
      v = with(v, reinterpret_cast<uintptr_t>(a.position) + offsetof(Float4, w), sizeof(Float4), 4);
      break;
    case AttributeKind::Density:
      v = with(v, reinterpret_cast<uintptr_t>(a.density), sizeof(float), 4);
      break;
    case AttributeKind::Id:
      v = with(v, reinterpret_cast<uintptr_t>(a.id), sizeof(uint32_t), 4);
      break;
    case AttributeKind::User:
      v = with(v, reinterpret_cast<uintptr_t>(a.user_attribute), sizeof(uint32_t), 4);
      break;
  }
  return v;
}

void CudaBackend::record_device_event(void* event) const {
  require_alive();
  DeviceGuard guard(device_);
  guarded(
      [&] { cuda_check(cudaEventRecord(static_cast<cudaEvent_t>(event), r_->stream), "cudaEventRecord"); });
}

void CudaBackend::wait_device_event(void* event) const {
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] {
    cuda_check(cudaStreamWaitEvent(r_->stream, static_cast<cudaEvent_t>(event), 0), "cudaStreamWaitEvent");
  });
}

// One event serves both directions: a stream wait takes the event's state when it is enqueued,
// so the event may be recorded again at once.
void CudaBackend::order_after_stream(void* stream) const {
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] {
    cuda_check(cudaEventRecord(r_->order_event, static_cast<cudaStream_t>(stream)),
               "cudaEventRecord on the caller's stream");
    cuda_check(cudaStreamWaitEvent(r_->stream, r_->order_event, 0), "cudaStreamWaitEvent");
  });
}

void CudaBackend::order_stream_after(void* stream) const {
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] {
    cuda_check(cudaEventRecord(r_->order_event, r_->stream), "cudaEventRecord");
    cuda_check(cudaStreamWaitEvent(static_cast<cudaStream_t>(stream), r_->order_event, 0),
               "cudaStreamWaitEvent on the caller's stream");
  });
}

int cuda_usable_device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    (void)cudaGetLastError();
    return 0;
  }
  return count;
}

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig& config, int device_ordinal,
                                           const CudaBackendOptions& options) {
  return std::make_unique<CudaBackend>(config, device_ordinal, options);
}

}  // namespace sph
