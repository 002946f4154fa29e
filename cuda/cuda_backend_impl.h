// SPDX-License-Identifier: MIT
// The CUDA backend's class, shared by cuda_backend.cu (particles, copies out, checkpoints, the
// interop tier) and frame_loop.cu (frames and their rollback). Device-resident particles,
// every substep stage on the world's own stream, and the frame loop on the device
// (frame_graph.h). It mirrors the CPU backend's semantics: the same sort, the same substep
// structure, the same step control and the same rollback.
#pragma once

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

#include "../src/core/backend.h"
#include "../src/core/slab_decomposition.h"
#include "cuda_backend.h"
#include "cuda_status.h"
#include "device_array.h"
#include "device_boundary_maps.h"
#include "device_halo.h"
#include "device_halo_springs.h"
#include "device_neighbor_grid.h"
#include "device_particle_store.h"
#include "device_scene.h"
#include "device_sinks.h"
#include "frame_control.h"
#include "frame_graph.h"
#include "frame_statistics.h"
#include "substep_pipeline.h"

namespace sph {

// Everything the backend holds on the device. Released with the backend's device current.
struct DeviceResources {
  cudaStream_t stream = nullptr;
  cudaEvent_t frame_start = nullptr;
  cudaEvent_t frame_stop = nullptr;
  cudaEvent_t order_event = nullptr;  // for ordering against a caller's stream (sph_cuda.h)
  std::unique_ptr<DeviceParticleStore> store;
  std::unique_ptr<DeviceNeighborGrid> grid;
  std::unique_ptr<FrameStatistics> statistics;
  DeviceArray<FrameState> state;
  DeviceArray<double> solve_partials;  // DFSPH only: the block sums of a solve's error
  PinnedArray<FrameInput> input;
  PinnedArray<FrameState> state_output;
  PinnedArray<uint32_t> sink_kept;
  FrameGraph graph;
  PipelineSetup graph_setup;
  DeviceSdfCache sdf_cache;
  DeviceBoundaryMaps boundary_maps;
  DeviceColliderLoads loads;
  DeviceProbeBuffers probes;
  DeviceSceneBuffer scene_buffer;
  DeviceSinkCompactor sinks;
  std::unique_ptr<DeviceHalo> halo;                 // a distributed world's rank only (cuda_halo.cu)
  std::unique_ptr<DeviceHaloSprings> halo_springs;  // and with springs (cuda_halo_springs.cu)

  ~DeviceResources() {
    if (stream && cudaStreamSynchronize(stream) != cudaSuccess) (void)cudaGetLastError();
    graph.reset();
    if (frame_start) cudaEventDestroy(frame_start);
    if (frame_stop) cudaEventDestroy(frame_stop);
    if (order_event) cudaEventDestroy(order_event);
    if (stream) cudaStreamDestroy(stream);
    (void)cudaGetLastError();
  }

  PipelineBuffers buffers() {
    return PipelineBuffers{store.get(), grid.get(),         statistics.get(),    state.get(),
                           input.get(), state_output.get(), solve_partials.get()};
  }
};

class CudaBackend final : public Backend {
 public:
  CudaBackend(const WorldConfig& config, int device, const CudaBackendOptions& options);
  ~CudaBackend() override;

  uint32_t particle_count() const override { return count_; }

  void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id,
              uint32_t user_attribute) override;

  // Drops particles [count, particle_count()) (an emission undone after a failed step).
  void truncate(uint32_t count) override;

  // A larger store, grid, statistics and solve sums are made and the particles copied before
  // anything is swapped in (so a failed allocation leaves the world as it was); the frame graph,
  // which holds the old buffers' addresses, is dropped and captured again by the next frame.
  void reserve(uint32_t capacity, const GrowthNeeds& needs) override;

  // Device-to-device copies of the carried max speed and max acceleration on the stream (no
  // wait for the host when saving).
  void save_step_inputs() override;
  void restore_step_inputs() override;

  // Binds the scene's SDFs and boundary maps and uploads its views (a frame that follows binds
  // the same copies again without allocating).
  void prepare_scene(const SceneFrame& scene, const RuntimeParams& params) override;

  FrameReport step_scene_frame(double frame_dt, const RuntimeParams& params,
                               const SceneFrame& scene_in) override;

  void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                      size_t stride) const override;

  // Checkpoints: the state in storage order and the frame state that carries over (max speed,
  // max acceleration); everything else in FrameState is reset when a frame begins.
  ParticleSnapshot export_particles() const override;

  void import_particles(const ParticleSnapshot& s) override;

  uint64_t memory_bytes() const override;

  DeviceAttributeView device_attribute(AttributeKind kind) const override;

  uint64_t data_epoch() const override { return epoch_; }
  void continue_data_epoch(const Backend& previous) override {
    if (const auto* p = dynamic_cast<const CudaBackend*>(&previous)) epoch_ = std::max(epoch_, p->epoch_) + 1;
  }
  int device_ordinal() const override { return device_; }
  void* device_stream() const override { return r_->stream; }

  void record_device_event(void* event) const override;

  void wait_device_event(void* event) const override;
  void order_after_stream(void* stream) const override;
  void order_stream_after(void* stream) const override;

  // ---- a distributed world's rank (cuda_halo.cu; include/sph_mpi.h, docs/distributed.md) ----
  void attach_ranks(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options) override;
  const RankTransport* rank_transport() const override { return ranks_.get(); }
  DistributedCounters distributed_counters() const override;
  std::shared_ptr<const RankTransport> shared_rank_transport() const override { return ranks_; }
  DistributedState distributed_state() const override;
  void restore_distributed_state(const DistributedState& state) override;
  void rethrow_step_failure() const override;

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
  void roll_back_frame();
  // The device side of a frame's scene: SDF copies, boundary maps, the scene's views, the
  // loads' and sinks' buffers, the probes. Sets setup.scene, setup.loads and setup.probes.
  void bind_frame_scene(const SceneFrame& scene_in, PipelineSetup& setup);
  void copy_step_inputs(bool save);

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
  HostVector<T> download(const T* src, size_t count) const {
    HostVector<T> host(count);
    guarded([&] {
      cuda_check(cudaMemcpyAsync(host.data(), src, sizeof(T) * count, cudaMemcpyDeviceToHost, r_->stream),
                 "copy of particle data to the host");
      cuda_check(cudaStreamSynchronize(r_->stream), "copy of particle data to the host");
    });
    return host;
  }

  template <class T>
  static void scatter(const HostVector<T>& host, unsigned char* out, size_t stride) {
    for (size_t k = 0; k < host.size(); ++k) std::memcpy(out + k * stride, &host[k], sizeof(T));
  }

  // (Re)captures the frame graph when needed; false when it cannot be built (see frame_loop.cu).
  bool prepare_graph(const PipelineSetup& setup);

  // The stream driver (frame_loop.cu): frames with sinks, and every frame without graphs.
  uint32_t run_frame_on_stream(PipelineSetup setup, uint32_t sink_count, HostVector<uint32_t>& removed_ids,
                               HostVector<uint32_t>& removed_by_sink, const StepInterrupt& interrupt,
                               bool& interrupted);

  // A distributed rank's frames (cuda_halo.cu): the stream driver with the CPU rank's halo steps
  // at the same points (src/cpu/cpu_halo.cpp), each a host synchronisation. Between substeps the
  // rank holds the particles it owns; during one, also its ghosts, appended before the sort.
  class HaloHooks;
  uint32_t run_frame_distributed(PipelineSetup setup, uint32_t sink_count, HostVector<uint32_t>& removed_ids,
                                 HostVector<uint32_t>& removed_by_sink, const StepInterrupt& interrupt,
                                 bool& interrupted);
  // The world's max speed and acceleration and DFSPH's height span; new slabs when out of balance.
  void halo_begin_frame(const StepLimits& limits);
  void halo_gather();                            // migration, then ghosts; the visit order of the sort
  void halo_after_sort(cudaStream_t stream);     // ghost mask, new keys, the lists of the records
  void halo_after_density(cudaStream_t stream);  // the ghosts take their owners' density records
  void halo_after_normals(cudaStream_t stream);  // and their colour normals (surface tension)
  // DFSPH (core/dfsph_jacobi_loop.h says when): the ghosts take their owners' densities and
  // factors, a solve's velocities v, its pressure steps k; the solve's mean error over the world.
  void halo_after_dfsph_density(cudaStream_t stream);
  void halo_share_velocities(Float4* v, cudaStream_t stream);
  void halo_share_dfsph_steps(cudaStream_t stream);
  DfsphErrors halo_dfsph_errors(bool divergence, cudaStream_t stream);
  // The conjugate gradients' sums and maxima over the world (DfsphRankSteps::cg_world).
  int64_t halo_dfsph_cg_world(int sums, double* values, int maxima, float* largest, cudaStream_t stream);
  // Probes: each sample point's gather becomes its owner rank's (core/rank_probe_points.h).
  void halo_pick_probe_points(const DeviceProbes& probes, cudaStream_t stream);
  // The ghosts take their owners' records (DeviceHalo::pack_records / enqueue_apply_records) of
  // the arrays `a` (the store's, or a view of them).
  template <class Record>
  void halo_refresh(cudaStream_t stream, const char* what, const ParticleArrays& a);
  void halo_before_end(cudaStream_t stream);  // maxima and failures reduced over the ranks
  // RK4: a stage's end and the next stage's halo (SubstepHooks::next_stage).
  bool halo_next_stage(int stage, uint32_t* count, cudaStream_t stream);
  // The substep's state so far (pinned; after the stream), the records' id check thrown.
  const FrameState& halo_substep_state(cudaStream_t stream);
  void halo_sum_loads(ColliderLoadSums* sums, uint32_t colliders);  // the frame's loads over the ranks
  // Sinks after a substep, as on the CPU rank: the ghosts dropped, then the rank's own particles
  // tested and compacted (its removed ids and counts appended); after the frame's last substep
  // the neighbour counts of its density pass (returned; null otherwise) travel with them.
  const uint32_t* halo_apply_sinks(const PipelineSetup& setup, uint32_t sink_count, bool last,
                                   HostVector<uint32_t>& removed_ids, HostVector<uint32_t>& removed_by_sink);
  // The owned particles, in the sorted order; `counts` (per particle, sorted order) kept with them.
  void halo_drop_ghosts(uint32_t* counts = nullptr);
  HostVector<HaloArray> halo_arrays() const;  // what travels with a particle (halo_rk4_side_)
  // Springs across ranks (cuda_halo_springs.cu): after the ghosts' arrival, the owned lists' ids to
  // indices and the spring ghosts appended after the n particles held (returns the new count);
  // the lowest waiting id over the ranks (after the ghosts' agreement); between linking's passes,
  // the ghosts' candidates from their owners; the lists back to ids (halo_drop_ghosts).
  uint32_t halo_gather_spring_partners(uint32_t owned, uint32_t n);
  void halo_agree_link_from();
  void halo_share_spring_candidates(cudaStream_t stream);
  void halo_springs_to_ids();
  std::vector<RankBytes> halo_send(const uint32_t* starts);
  uint32_t halo_receive(const RankBytes& in, uint32_t first);
  bool halo_any(bool flag) const;
  void halo_agree() const;

  std::shared_ptr<const RankTransport> ranks_;
  DistributedOptions distributed_options_;
  SlabDecomposition slabs_;
  bool slabs_cut_ = false;
  DistributedCounters halo_counters_;
  int64_t halo_world_count_ = 0;  // the particles every rank owns, this substep
  uint32_t halo_owned_ = 0;       // during a frame: the owned particles (count_: the frame's start)
  uint32_t halo_ghosts_ = 0;      // and the ghosts after them
  // After the density pass: how many owned particles the sorted order holds (the device's kept
  // list, DeviceHalo::kept_list); kNoKeptList before it.
  static constexpr uint32_t kNoKeptList = UINT32_MAX;
  uint32_t halo_kept_ = kNoKeptList;
  // Between RK4's stages: the side of the stage state (rk4_start, rk4_sum) the last stage left,
  // which travels and is kept with the particles (halo_next_stage); kNoRk4Side otherwise.
  static constexpr int kNoRk4Side = -1;
  int halo_rk4_side_ = kNoRk4Side;
  // Springs: whether the owned lists hold storage indices (from the gather to the ghosts' drop) or
  // ids; whether this substep links (the lowest waiting id over the ranks is an id).
  bool halo_springs_indexed_ = false;
  bool halo_linking_ = false;

  WorldConfig config_;
  int device_;
  KernelTuning tuning_;
  SubstepOptions options_;
  bool use_graphs_ = true;
  // Set once the running frame's rollback point (the particle snapshot and the saved step inputs)
  // is on the stream; a frame that fails before it has changed no particle and rolls nothing back.
  bool rollback_point_enqueued_ = false;
  uint32_t count_ = 0;
  uint64_t epoch_ = 1;
  mutable bool lost_ = false;
  std::unique_ptr<DeviceResources> r_;
};

}  // namespace sph
