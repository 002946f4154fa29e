// The CUDA backend: device-resident particles, every substep stage on the world's own stream,
// and the frame loop on the device (frame_graph.h). It mirrors the CPU backend's semantics:
// the same sort, the same substep structure, the same step control and the same rollback.
#include <cfloat>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "../src/core/grid_layout.h"
#include "../src/physics/density_normalization.h"
#include "cuda_backend.h"
#include "cuda_status.h"
#include "device_array.h"
#include "device_neighbor_grid.h"
#include "device_particle_store.h"
#include "device_scene.h"
#include "device_sinks.h"
#include "device_springs.h"
#include "frame_control.h"
#include "frame_graph.h"
#include "frame_statistics.h"
#include "substep_pipeline.h"

namespace sph {
namespace {

unsigned env_block_size(const char* name, unsigned fallback) {
  const char* value = std::getenv(name);
  if (!value) return fallback;
  const long v = std::strtol(value, nullptr, 10);
  return (v == 32 || v == 64 || v == 128 || v == 256 || v == 512 || v == 1024) ? static_cast<unsigned>(v)
                                                                               : fallback;
}

bool env_graphs_enabled() {
  const char* value = std::getenv("SPH_CUDA_GRAPHS");
  return !(value && std::strcmp(value, "0") == 0);
}

bool same_setup(const PipelineSetup& a, const PipelineSetup& b) {
  return a.count == b.count && a.integrator == b.integrator && a.max_substeps == b.max_substeps &&
         std::memcmp(&a.fluid, &b.fluid, sizeof a.fluid) == 0 &&
         std::memcmp(&a.limits, &b.limits, sizeof a.limits) == 0 &&
         a.tuning.density_block == b.tuning.density_block && a.tuning.force_block == b.tuning.force_block &&
         a.options.surface_tension == b.options.surface_tension &&
         a.options.normalized_density == b.options.normalized_density &&
         a.options.viscosity == b.options.viscosity && a.options.springs == b.options.springs &&
         std::memcmp(&a.options.methods, &b.options.methods, sizeof a.options.methods) == 0 &&
         std::memcmp(&a.springs, &b.springs, sizeof a.springs) == 0 &&
         a.scene.colliders == b.scene.colliders && a.scene.fields == b.scene.fields &&
         a.scene.collider_count == b.scene.collider_count && a.scene.field_count == b.scene.field_count &&
         a.scene.kernel_radius == b.scene.kernel_radius;
}

// Everything the backend holds on the device. Released with the backend's device current.
struct Resources {
  cudaStream_t stream = nullptr;
  cudaEvent_t frame_start = nullptr;
  cudaEvent_t frame_stop = nullptr;
  std::unique_ptr<DeviceParticleStore> store;
  std::unique_ptr<DeviceNeighborGrid> grid;
  std::unique_ptr<FrameStatistics> statistics;
  DeviceArray<FrameState> state;
  PinnedArray<FrameInput> input;
  PinnedArray<FrameState> state_output;
  PinnedArray<uint32_t> sink_kept;
  FrameGraph graph;
  PipelineSetup graph_setup;
  DeviceSdfCache sdf_cache;
  DeviceSceneBuffer scene_buffer;
  DeviceSinkCompactor sinks;

  ~Resources() {
    if (stream && cudaStreamSynchronize(stream) != cudaSuccess) (void)cudaGetLastError();
    graph.reset();
    if (frame_start) cudaEventDestroy(frame_start);
    if (frame_stop) cudaEventDestroy(frame_stop);
    if (stream) cudaStreamDestroy(stream);
    (void)cudaGetLastError();
  }

  PipelineBuffers buffers() {
    return PipelineBuffers{store.get(), grid.get(),  statistics.get(),
                           state.get(), input.get(), state_output.get()};
  }
};

class CudaBackend final : public Backend {
 public:
  CudaBackend(const WorldConfig& config, int device) : config_(config), device_(device) {
    DeviceGuard guard(device_);
    auto r = std::make_unique<Resources>();
    cuda_check(cudaStreamCreateWithFlags(&r->stream, cudaStreamNonBlocking), "cudaStreamCreate");
    cuda_check(cudaEventCreate(&r->frame_start), "cudaEventCreate");
    cuda_check(cudaEventCreate(&r->frame_stop), "cudaEventCreate");
    options_.methods = config.selection();
    options_.surface_tension = (config.features & kFeatureSurfaceTension) != 0;
    options_.normalized_density = (config.features & kFeatureNormalizedDensity) != 0;
    options_.viscosity = config.viscosity_method;
    options_.springs = (config.features & kFeatureSprings) != 0;
    StoreOptions store_options;
    store_options.rk4 = config.integrator == Integrator::Rk4;
    store_options.neighbor_counts = options_.viscosity == ViscosityMethod::Clavet;
    store_options.normalized_density = options_.normalized_density;
    store_options.colour_normals = options_.surface_tension;
    store_options.springs = options_.springs;
    r->store = std::make_unique<DeviceParticleStore>(config.capacity, store_options);
    // The sorted positions are free while the sort runs: its temporary storage goes there.
    r->grid = std::make_unique<DeviceNeighborGrid>(
        make_grid_shape(config.kernel_radius, config.capacity), config.capacity, r->store->sort_scratch(),
        r->store->arrays().sorted_position, sizeof(Float4) * static_cast<size_t>(config.capacity));
    r->statistics = std::make_unique<FrameStatistics>(config.capacity);
    r->state.allocate(1, "frame state");
    cuda_check(cudaMemsetAsync(r->state.get(), 0, sizeof(FrameState), r->stream), "frame state reset");
    r->store->enqueue_reset_link_state(r->stream);
    r->input.allocate(1, "frame input");
    r->state_output.allocate(1, "frame output");
    r->sink_kept.allocate(1, "sink survivor count");
    cuda_check(cudaStreamSynchronize(r->stream), "backend set-up");
    tuning_.density_block = env_block_size("SPH_CUDA_DENSITY_BLOCK", tuning_.density_block);
    tuning_.force_block = env_block_size("SPH_CUDA_FORCE_BLOCK", tuning_.force_block);
    use_graphs_ = env_graphs_enabled();
    r_ = std::move(r);
  }

  ~CudaBackend() override {
    DeviceGuard* guard = nullptr;
    try {
      guard = new DeviceGuard(device_);
    } catch (...) {
    }
    r_.reset();
    delete guard;
  }

  uint32_t particle_count() const override { return count_; }

  void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id) override {
    require_alive();
    DeviceGuard guard(device_);
    std::vector<Float4> pos(n), vel(n);
    std::vector<uint32_t> ids(n);
    const std::vector<float> density(n, config_.rest_density);
    // Normalised density: a fresh particle's factor is resolved by its first density pass.
    const std::vector<float> fresh(options_.normalized_density ? n : 0u, fresh_density_factor());
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
      if (options_.springs && n > 0) {
        // New particles have no springs yet; they make them at their first substep.
        const std::vector<SpringList> empty(n, empty_spring_list());
        cuda_check(cudaMemcpyAsync(a.springs + count_, empty.data(), sizeof(SpringList) * n,
                                   cudaMemcpyHostToDevice, s),
                   "copy of new spring lists");
        enqueue_springs_appended(a, first_id, s);
      }
      if (a.density_factor)
        cuda_check(cudaMemcpyAsync(a.density_factor + count_, fresh.data(), sizeof(float) * n,
                                   cudaMemcpyHostToDevice, s),
                   "copy of new density factors");
      enqueue_recompute_max_speed(a.velocity, count_ + n, r_->state.get(), s);
      cuda_check(cudaStreamSynchronize(s), "append");
    });
    count_ += n;
    ++epoch_;
  }

  // Drops particles [count, particle_count()) (an emission undone after a failed step).
  void truncate(uint32_t count) override {
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

  FrameReport step_frame(double frame_dt, const RuntimeParams& params) override {
    return step_scene_frame(frame_dt, params, SceneFrame{});
  }

  // A frame with colliders and force fields runs in the frame graph like any other: the
  // scene's assets and views are uploaded first, outside the graph. A frame with sinks runs on
  // the stream (the particle count changes inside it; see docs/cuda.md).
  FrameReport step_scene_frame(double frame_dt, const RuntimeParams& params,
                               const SceneFrame& scene_in) override {
    require_alive();
    DeviceGuard guard(device_);
    PipelineSetup setup;
    setup.count = count_;
    setup.integrator = config_.integrator;
    setup.fluid = make_fluid_constants(config_, params);
    setup.limits = make_step_limits(config_, params);
    setup.max_substeps = params.stepping.max_substeps;
    setup.options = options_;
    setup.tuning = tuning_;
    if (options_.springs) setup.springs = setup.fluid.methods.springs;
    float frame_ms = 0.0f;
    const bool with_sinks = !scene_in.sinks.empty();
    uint32_t count_after = count_;
    std::vector<uint32_t> removed_ids, removed_by_sink(scene_in.sinks.size(), 0u);
    bool frame_enqueued = false;  // the frame's first work (the rollback snapshot) is on the stream
    try {
      guarded([&] {
        if (!scene_in.empty()) {
          SceneFrame scene = scene_in;
          r_->sdf_cache.begin_frame();
          bind_scene_views(scene, [&](const SdfAsset& a) { return r_->sdf_cache.bind(a, r_->stream); });
          r_->sdf_cache.end_frame();
          setup.scene = r_->scene_buffer.upload(scene, config_.kernel_radius, r_->stream);
          if (with_sinks) r_->sinks.reserve(config_.capacity);
          cuda_check(cudaStreamSynchronize(r_->stream), "upload of the scene");
        }
        FrameInput* input = r_->input.get();
        input->frame_dt = frame_dt;
        input->max_collider_speed = scene_in.max_collider_speed;
        input->pad = 0;
        if (!with_sinks) prepare_graph(setup);
        cuda_check(cudaEventRecord(r_->frame_start, r_->stream), "cudaEventRecord");
        frame_enqueued = true;
        if (with_sinks)
          count_after = run_sink_frame_on_stream(setup, static_cast<uint32_t>(scene_in.sinks.size()),
                                                 removed_ids, removed_by_sink);
        else if (use_graphs_)
          r_->graph.launch(r_->stream);
        else
          run_frame_on_stream(setup);
        cuda_check(cudaEventRecord(r_->frame_stop, r_->stream), "cudaEventRecord");
        cuda_check(cudaStreamSynchronize(r_->stream), "frame");
        cuda_check(cudaEventElapsedTime(&frame_ms, r_->frame_start, r_->frame_stop), "cudaEventElapsedTime");
      });
    } catch (const Error& e) {
      // A failure in the middle of a frame that did not lose the device (a host allocation
      // for the removed ids, say): the substeps already run are undone from the frame's
      // snapshot, so the failed step changes nothing.
      if (frame_enqueued && e.status() != Status::DeviceLost) roll_back_frame();
      throw;
    } catch (const std::exception&) {
      if (frame_enqueued) roll_back_frame();
      throw;
    }
    const FrameState s = *r_->state_output.get();
    ++epoch_;
    if (s.non_finite) {
      roll_back_frame();
      static const char* const kStages[] = {
          "density stage (SPH_STAGE_DENSITY)", "forces stage (SPH_STAGE_FORCES)",
          "integrate stage (SPH_STAGE_INTEGRATE)", "collide stage (SPH_STAGE_COLLIDE)"};
      throw Error(
          Status::NonFinite,
          "the step produced non-finite values in the " + std::string(kStages[s.bad_stage & 3u]) +
              " of substep " + std::to_string(s.bad_substep) + " (dt " + std::to_string(s.bad_dt) + " s" +
              (setup.limits.stability_dt > 0.0f && s.bad_dt > setup.limits.stability_dt
                   ? ", above this world's stable step " + std::to_string(setup.limits.stability_dt) +
                         " s (0.4 h / c, 0.05 h^2 rho0 / mu), forced by dt_min"
                   : std::string()) +
              "): " + std::to_string(s.bad_count) +
              (s.bad_count == 1 ? " particle, id " : " particles, first id ") + std::to_string(s.bad_id) +
              "; the world was restored to its state before sph_world_step");
    }
    count_ = count_after;
    FrameReport report;
    report.removed_ids = std::move(removed_ids);
    report.removed_by_sink = std::move(removed_by_sink);
    report.substeps = s.substeps;
    report.completed = s.remaining <= 0.0;
    report.time_advanced = s.time_advanced;
    report.dt_min = s.substeps == 0 ? 0.0f : s.dt_min;
    report.dt_max = s.dt_max;
    report.max_speed = s.max_speed;
    report.density_min = s.density_min;
    report.density_mean = s.density_mean;
    report.density_max = s.density_max;
    report.neighbors_mean = s.neighbors_mean;
    report.neighbors_max = s.neighbors_max;
    double staged_ms = 0.0;
    for (int k = 0; k < kStageCount; ++k) {
      report.stage_ms[k] = static_cast<float>(static_cast<double>(s.stage_ns[k]) * 1e-6);
      staged_ms += report.stage_ms[k];
    }
    // The device marks cover the frame from its first kernel to the statistics; what the
    // events saw beyond that (the input and output copies, launch) is "other".
    if (frame_ms > staged_ms) report.stage_ms[kStageOther] += static_cast<float>(frame_ms - staged_ms);
    return report;
  }

  void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                      size_t stride) const override {
    require_alive();
    DeviceGuard guard(device_);
    const ParticleArrays& a = r_->store->arrays();
    unsigned char* out = static_cast<unsigned char*>(dst);
    switch (kind) {
      case AttributeKind::Position:
      case AttributeKind::Velocity:
      case AttributeKind::Pressure: {
        const Float4* src = (kind == AttributeKind::Velocity ? a.velocity : a.position) + first;
        const std::vector<Float4> host = download(src, count);
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
    }
  }

  // Checkpoints: the state in storage order and the frame state that carries over (max speed,
  // max acceleration); everything else in FrameState is reset when a frame begins.
  ParticleSnapshot export_particles() const override {
    require_alive();
    DeviceGuard guard(device_);
    const ParticleArrays& a = r_->store->arrays();
    ParticleSnapshot s;
    s.position = download(a.position, count_);
    s.velocity = download(a.velocity, count_);
    s.id = download(a.id, count_);
    s.density = download(a.density, count_);
    if (a.density_factor) s.density_factor = download(a.density_factor, count_);
    const std::vector<FrameState> state = download(static_cast<const FrameState*>(r_->state.get()), 1u);
    s.max_speed = state[0].max_speed;
    s.max_acceleration = state[0].max_acceleration;
    if (options_.springs) {
      s.springs = download(static_cast<const SpringList*>(a.springs), count_);
      s.link_from = download(static_cast<const uint32_t*>(a.link_from), 1u)[0];
    }
    return s;
  }

  void import_particles(const ParticleSnapshot& s) override {
    require_alive();
    const uint32_t n = static_cast<uint32_t>(s.id.size());
    if (n > config_.capacity || s.position.size() != n || s.velocity.size() != n || s.density.size() != n ||
        (!s.density_factor.empty() && s.density_factor.size() != n))
      throw Error(Status::Internal, "import_particles: inconsistent snapshot");
    if (options_.springs ? s.springs.size() != n : !s.springs.empty())
      throw Error(Status::Internal, "import_particles: spring lists do not match the particles");
    const std::vector<float> factor = !options_.normalized_density ? std::vector<float>()
                                      : s.density_factor.empty()
                                          ? std::vector<float>(n, fresh_density_factor())
                                          : s.density_factor;
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
        cuda_check(
            cudaMemcpyAsync(a.density, s.density.data(), sizeof(float) * n, cudaMemcpyHostToDevice, st),
            "copy of checkpoint densities");
        if (options_.springs)
          cuda_check(cudaMemcpyAsync(a.springs, s.springs.data(), sizeof(SpringList) * n,
                                     cudaMemcpyHostToDevice, st),
                     "copy of checkpoint spring lists");
        if (a.density_factor)
          // A snapshot without factors (a checkpoint written before they existed) starts every
          // particle fresh, as if it had just been spawned.
          cuda_check(
              cudaMemcpyAsync(a.density_factor, factor.data(), sizeof(float) * n, cudaMemcpyHostToDevice, st),
              "copy of checkpoint density factors");
      }
      if (options_.springs)
        cuda_check(cudaMemcpyAsync(a.link_from, &s.link_from, sizeof(uint32_t), cudaMemcpyHostToDevice, st),
                   "copy of the checkpoint's spring link state");
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

  uint64_t memory_bytes() const override {
    return r_->store->bytes() + r_->grid->bytes() + r_->statistics->bytes() + r_->state.bytes() +
           r_->sdf_cache.bytes() + r_->scene_buffer.bytes() + r_->sinks.bytes();
  }

  DeviceAttributeView device_attribute(AttributeKind kind) const override {
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
    }
    return v;
  }

  uint64_t data_epoch() const override { return epoch_; }
  int device_ordinal() const override { return device_; }
  void* device_stream() const override { return r_->stream; }

  void record_device_event(void* event) const override {
    require_alive();
    DeviceGuard guard(device_);
    guarded(
        [&] { cuda_check(cudaEventRecord(static_cast<cudaEvent_t>(event), r_->stream), "cudaEventRecord"); });
  }

  void wait_device_event(void* event) const override {
    require_alive();
    DeviceGuard guard(device_);
    guarded([&] {
      cuda_check(cudaStreamWaitEvent(r_->stream, static_cast<cudaEvent_t>(event), 0), "cudaStreamWaitEvent");
    });
  }

 private:
  static DeviceAttributeView with(DeviceAttributeView v, uintptr_t address, uint64_t stride,
                                  uint32_t element) {
    v.address = address;
    v.stride = stride;
    v.element_size = element;
    return v;
  }

  // Restores the particles (and the cached max speed) from the snapshot taken at the start of
  // the frame; count_ is still the count before the frame.
  void roll_back_frame() {
    ++epoch_;
    guarded([&] {
      r_->store->enqueue_restore(count_, r_->stream);
      enqueue_restore_max_speed(r_->state.get(), r_->stream);
      cuda_check(cudaStreamSynchronize(r_->stream), "rollback");
    });
  }

  void require_alive() const {
    if (lost_)
      throw Error(Status::DeviceLost,
                  "world: its CUDA device reported a sticky error earlier; destroy the world");
  }

  // Runs body; a sticky CUDA error marks the backend lost so every later call reports it.
  template <class Body>
  void guarded(Body&& body) const {
    try {
      body();
    } catch (const Error& e) {
      if (e.status() == Status::DeviceLost) lost_ = true;
      throw;
    }
  }

  template <class T>
  std::vector<T> download(const T* src, uint32_t count) const {
    std::vector<T> host(count);
    guarded([&] {
      cuda_check(cudaMemcpyAsync(host.data(), src, sizeof(T) * count, cudaMemcpyDeviceToHost, r_->stream),
                 "copy of particle data to the host");
      cuda_check(cudaStreamSynchronize(r_->stream), "copy of particle data to the host");
    });
    return host;
  }

  template <class T>
  static void scatter(const std::vector<T>& host, unsigned char* out, size_t stride) {
    for (size_t k = 0; k < host.size(); ++k) std::memcpy(out + k * stride, &host[k], sizeof(T));
  }

  // (Re)captures the frame graph when the particle count or a parameter changed. A graph that
  // cannot be built for a non-sticky reason (an old driver without conditional nodes) leaves
  // the world on the stream fallback.
  void prepare_graph(const PipelineSetup& setup) {
    if (!use_graphs_) return;
    if (r_->graph.ready() && same_setup(setup, r_->graph_setup)) return;
    try {
      r_->graph.build(setup, r_->buffers(), r_->stream);
      r_->graph_setup = setup;
    } catch (const Error& e) {
      if (e.status() == Status::DeviceLost || e.status() == Status::OutOfDeviceMemory) throw;
      use_graphs_ = false;
    }
  }

  // The fallback: the same work launched stage by stage, reading the loop condition back
  // after every substep.
  void run_frame_on_stream(const PipelineSetup& setup) {
    const PipelineBuffers b = r_->buffers();
    enqueue_frame_begin(setup, b, LoopCondition{}, r_->stream);
    for (;;) {
      cuda_check(cudaMemcpyAsync(&b.state_output->run, &b.state->run, sizeof(uint32_t),
                                 cudaMemcpyDeviceToHost, r_->stream),
                 "copy of the loop condition");
      cuda_check(cudaStreamSynchronize(r_->stream), "substep");
      if (!b.state_output->run) break;
      enqueue_substep(setup, b, LoopCondition{}, r_->stream);
    }
    enqueue_frame_end(setup, b, r_->stream);
  }

  // A frame with sinks: the fallback's loop, and after every substep the sinks' stable
  // compaction, whose survivor count comes back to the host with the loop condition (one
  // synchronisation per substep, a second one only when particles were removed). Returns the
  // particle count after the frame; the removed ids, in the CPU backend's order, and the
  // per-sink counts are appended.
  uint32_t run_sink_frame_on_stream(PipelineSetup setup, uint32_t sink_count,
                                    std::vector<uint32_t>& removed_ids,
                                    std::vector<uint32_t>& removed_by_sink) {
    const PipelineBuffers b = r_->buffers();
    const ParticleArrays& a = b.store->arrays();
    cudaStream_t s = r_->stream;
    FrameState* out = b.state_output;
    uint32_t* kept_out = r_->sink_kept.get();
    uint32_t n = count_;
    setup.count = n;
    enqueue_frame_begin(setup, b, LoopCondition{}, s);
    cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
               "copy of the loop condition");
    cuda_check(cudaStreamSynchronize(s), "frame begin");
    bool counts_from_compaction = false;
    std::vector<uint32_t> ids, sinks;
    while (out->run) {
      setup.count = n;
      enqueue_substep(setup, b, LoopCondition{}, s);
      r_->sinks.enqueue_flag(r_->scene_buffer.sinks(), sink_count, a, n, b.state, s);
      cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
                 "copy of the loop condition");
      cuda_check(cudaMemcpyAsync(&out->non_finite, &b.state->non_finite, sizeof(uint32_t),
                                 cudaMemcpyDeviceToHost, s),
                 "copy of the non-finite flag");
      cuda_check(
          cudaMemcpyAsync(kept_out, r_->sinks.kept_device(), sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
          "copy of the sink survivor count");
      cuda_check(cudaStreamSynchronize(s), "substep");
      counts_from_compaction = false;
      if (out->non_finite) break;  // as on the CPU: no sinks after a failed substep
      const uint32_t kept = *kept_out;
      if (kept == n) continue;
      // After the last substep the statistics need the neighbour counts of its density pass,
      // which the compaction carries along (the sorted copy it reads becomes scratch).
      uint32_t* counts = nullptr;
      if (!out->run) {
        counts = r_->sinks.counts();
        b.statistics->enqueue_neighbor_counts(setup.fluid, b.grid->view(), a, n, counts, s);
      }
      r_->sinks.enqueue_compact(a, n, kept, counts, s);
      const uint32_t removed = n - kept;
      ids.resize(removed);
      sinks.resize(removed);
      cuda_check(cudaMemcpyAsync(ids.data(), r_->sinks.removed_ids(), sizeof(uint32_t) * removed,
                                 cudaMemcpyDeviceToHost, s),
                 "copy of the removed ids");
      cuda_check(cudaMemcpyAsync(sinks.data(), r_->sinks.removed_sinks(), sizeof(uint32_t) * removed,
                                 cudaMemcpyDeviceToHost, s),
                 "copy of the removed ids' sinks");
      cuda_check(cudaStreamSynchronize(s), "sinks");
      removed_ids.insert(removed_ids.end(), ids.begin(), ids.end());
      for (uint32_t k : sinks) ++removed_by_sink[k];
      n = kept;
      counts_from_compaction = counts != nullptr;
    }
    setup.count = n;
    b.statistics->enqueue(setup.fluid, b.grid->view(), a, n, b.state, s,
                          counts_from_compaction ? r_->sinks.counts() : nullptr);
    cuda_check(cudaMemcpyAsync(out, b.state, sizeof(FrameState), cudaMemcpyDeviceToHost, s),
               "copy of the frame state");
    return n;
  }

  WorldConfig config_;
  int device_;
  KernelTuning tuning_;
  SubstepOptions options_;
  bool use_graphs_ = true;
  uint32_t count_ = 0;
  uint64_t epoch_ = 1;
  mutable bool lost_ = false;
  std::unique_ptr<Resources> r_;
};

}  // namespace

int cuda_usable_device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    (void)cudaGetLastError();
    return 0;
  }
  return count;
}

std::unique_ptr<Backend> make_cuda_backend(const WorldConfig& config, int device_ordinal) {
  return std::make_unique<CudaBackend>(config, device_ordinal);
}

}  // namespace sph
