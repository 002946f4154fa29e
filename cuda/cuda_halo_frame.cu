// SPDX-License-Identifier: MIT
// A distributed CUDA rank's frame (cuda_halo.cu has the rank's arrays and its exchanges): the
// stream driver with the halo's steps as hooks of the substep (SubstepHooks), the frame's start
// (the world's max speed and acceleration, new slabs when out of balance), RK4's stage ends (a
// failure agreed, the halo gathered anew) and the reduction of each substep's maxima and
// failures over the ranks before the device's end-of-substep kernel, which then picks the same
// next step on every rank (and fails on every rank together); the sinks after each substep, on
// the rank's own particles (its removed ids are its own, as on the CPU rank).
#include <algorithm>
#include <cstring>
#include <vector>

#include "../src/core/rank_agreement.h"
#include "../src/core/rank_sums.h"
#include "../src/core/slab_rebalance.h"
#include "cuda_backend_impl.h"
#include "kernel_launch.h"

namespace sph {
namespace {

constexpr uint32_t kAllFinite = 0xffffffffu;

// The rollback's point before the frame's first agreement (enqueue_frame_begin sets it again).
__global__ void save_rollback_inputs_kernel(FrameState* s) {
  s->saved_max_speed = s->max_speed;
  s->saved_max_acceleration = s->max_acceleration;
}

__global__ void set_step_inputs_kernel(FrameState* s, float max_speed, float max_acceleration,
                                       uint32_t height_lo_key, uint32_t height_hi_key) {
  s->max_speed = max_speed;
  s->max_acceleration = max_acceleration;
  s->height_lo_key = height_lo_key;
  s->height_hi_key = height_hi_key;
}

// The substep's maxima and failures as every rank found them; this rank's own failure (at any
// RK4 stage) keeps its own particle (the message names it), another rank's is named by its id.
__global__ void set_reduced_kernel(FrameState* s, uint32_t v2max_bits, uint32_t a2max_bits,
                                   unsigned long long crowded, uint32_t bad_id, uint32_t height_lo_key,
                                   uint32_t height_hi_key) {
  s->v2max_bits = v2max_bits;
  s->a2max_bits = a2max_bits;
  s->height_lo_key = height_lo_key;
  s->height_hi_key = height_hi_key;
  if (s->crowded_key == 0) s->crowded_key = crowded;
  bool own = false;
  for (int k = 0; k < kRk4Stages; ++k) own = own || s->bad_key[k] != kNoBadParticle;
  if (bad_id != kAllFinite && !own) {
    s->bad_key[0] = bad_id;
    s->bad_counts[0] = 1;
  }
}

// The id of this rank's first non-finite particle (the first stage that had one, as the
// end-of-substep kernel picks it), or kAllFinite.
int64_t first_bad_id(const FrameState& f) {
  for (int k = 0; k < kRk4Stages; ++k)
    if (f.bad_key[k] != kNoBadParticle) return static_cast<int64_t>(f.bad_key[k] & 0xffffffffu);
  return kAllFinite;
}

}  // namespace

class CudaBackend::HaloHooks final : public SubstepHooks {
 public:
  explicit HaloHooks(CudaBackend& b) : b_(b) { visit = b.r_->halo->visit(); }
  void after_sort(cudaStream_t stream) override { b_.halo_after_sort(stream); }
  void after_density(cudaStream_t stream) override { b_.halo_after_density(stream); }
  void after_normals(cudaStream_t stream) override { b_.halo_after_normals(stream); }
  bool next_stage(int stage, uint32_t* count, cudaStream_t stream) override {
    return b_.halo_next_stage(stage, count, stream);
  }
  void before_end(cudaStream_t stream) override { b_.halo_before_end(stream); }
  void after_dfsph_density(cudaStream_t stream) override { b_.halo_after_dfsph_density(stream); }
  void after_probe_points(const DeviceProbes& probes, cudaStream_t stream) override {
    b_.halo_pick_probe_points(probes, stream);
  }
  void share_velocities(Float4* v, cudaStream_t stream) override { b_.halo_share_velocities(v, stream); }
  void share_steps(cudaStream_t stream) override { b_.halo_share_dfsph_steps(stream); }
  void between_link_passes(cudaStream_t stream) override { b_.halo_share_spring_candidates(stream); }
  unsigned long long* error_bins() override { return b_.r_->halo->error_bins(); }
  DfsphErrors errors(bool divergence, cudaStream_t stream) override {
    return b_.halo_dfsph_errors(divergence, stream);
  }
  int64_t cg_world(int sums, double* values, int maxima, float* largest, cudaStream_t stream) override {
    return b_.halo_dfsph_cg_world(sums, values, maxima, largest, stream);
  }

 private:
  CudaBackend& b_;
};

void CudaBackend::halo_begin_frame(const StepLimits& limits) {
  const RankTransport& t = *ranks_;
  std::vector<int64_t> held(static_cast<size_t>(t.size()), 0);
  const HostVector<Float4> positions =
      count_ > 0 ? download(static_cast<const Float4*>(r_->store->arrays().position), count_)
                 : HostVector<Float4>{};
  // DFSPH's depth limit: this rank's height span on the device (every particle held between frames
  // is owned), reduced over the ranks below with the maxima, so every rank's first step reads the
  // world's H (enqueue_frame_begin then measures nothing).
  const bool depth = limits.depth_step_factor > 0.0f;
  if (depth)
    guarded([&] {
      enqueue_height_span(r_->store->arrays().position, nullptr, count_, limits, r_->state.get(), r_->stream);
    });
  const HostVector<FrameState> state = download(static_cast<const FrameState*>(r_->state.get()), 1u);
  halo_agree();  // (the frame's start: the step's code before it ran on each rank alone)
  float maxima[2] = {state[0].max_speed, state[0].max_acceleration};
  t.all_max(maxima, 2);
  // The keys as integers, the lowest as the largest of its complement (one reduction for both).
  int64_t keys[2] = {static_cast<int64_t>(kHeightLoReset - state[0].height_lo_key),
                     static_cast<int64_t>(state[0].height_hi_key)};
  if (depth) t.all_max(keys, 2);
  set_step_inputs_kernel<<<1, 1, 0, r_->stream>>>(r_->state.get(), maxima[0], maxima[1],
                                                  kHeightLoReset - static_cast<uint32_t>(keys[0]),
                                                  static_cast<uint32_t>(keys[1]));
  check_launch("set_step_inputs_kernel");
  if (rebalance_slabs(t, slabs_, slabs_cut_, distributed_options_.rebalance_threshold, count_,
                      1.0f / config_.kernel_radius, held, [&](uint32_t i) { return positions[i]; })) {
    slabs_cut_ = true;
    ++halo_counters_.rebalances;
  }
}

// Each rank summed its own particles' impulses; the frame's sums are added over the ranks in rank
// order (core/rank_sums.h, as the CPU rank does), so every rank reads the same world's value.
void CudaBackend::halo_sum_loads(ColliderLoadSums* sums, uint32_t colliders) {
  static_assert(sizeof(ColliderLoadSums) == 6 * sizeof(double), "a collider's sums are six doubles");
  HostVector<double> v(6 * static_cast<size_t>(colliders));
  if (colliders > 0) std::memcpy(v.data(), sums, sizeof(double) * v.size());
  ordered_rank_sum(*ranks_, v.data(), v.size());
  if (colliders > 0) std::memcpy(sums, v.data(), sizeof(double) * v.size());
}

const FrameState& CudaBackend::halo_substep_state(cudaStream_t stream) {
  DeviceHalo& h = *r_->halo;
  FrameState* out = r_->state_output.get();
  cuda_check(cudaMemcpyAsync(out, r_->state.get(), sizeof(FrameState), cudaMemcpyDeviceToHost, stream),
             "copy of the substep's state");
  uint32_t* mismatch = r_->sink_kept.get();  // (pinned; the sinks read their count after the substep)
  cuda_check(cudaMemcpyAsync(mismatch, h.mismatch_flag(), sizeof(uint32_t), cudaMemcpyDeviceToHost, stream),
             "copy of the halo's id check");
  cuda_check(cudaStreamSynchronize(stream), "the substep's state");
  if (*mismatch != 0) {
    cuda_check(cudaMemsetAsync(h.mismatch_flag(), 0, sizeof(uint32_t), stream), "halo id check reset");
    throw Error(Status::Internal,
                "halo: a rank's records (densities, colour normals, DFSPH's velocities or steps) came in "
                "another order than its ghosts");
  }
  return *out;
}

// As the CPU rank's RK4 (CpuBackend::substep_rk4): a stage ends as a substep does, so a failure of
// any rank (a non-finite particle, a crowded slot) ends the substep at that stage on every rank,
// and no rank sorts or sends a failed stage's state. Otherwise the ghosts go and the next stage
// gathers its halo, the stage state (the side the last stage's forces wrote, which the next
// reorder reads: stage & 1, substep_kernels.cu) travelling and kept with the particles.
bool CudaBackend::halo_next_stage(int stage, uint32_t* count, cudaStream_t stream) {
  const FrameState& f = halo_substep_state(stream);
  const bool failed = first_bad_id(f) != kAllFinite || f.crowded_key != 0;
  if (halo_any(failed)) return false;  // (an agreement: the stage's passes and the records' buffers)
  struct Side {
    int& side;
    ~Side() { side = kNoRk4Side; }
  } with_state{halo_rk4_side_};
  halo_rk4_side_ = stage & 1;
  halo_drop_ghosts();
  halo_gather();
  *count = halo_owned_ + halo_ghosts_;
  return true;
}

void CudaBackend::halo_before_end(cudaStream_t stream) {
  const RankTransport& t = *ranks_;
  const FrameState& f = halo_substep_state(stream);
  int64_t bad = first_bad_id(f);
  agree(t, &bad);  // (the substep's passes and the records' buffers)
  // DFSPH's depth limit: the height keys likewise (the lowest as the largest of its complement; the
  // reset keys, where the limit is off or a rank holds nothing, lose to any particle's).
  int64_t maxima[5] = {f.v2max_bits, f.a2max_bits, static_cast<int64_t>(f.crowded_key),
                       static_cast<int64_t>(kHeightLoReset - f.height_lo_key),
                       static_cast<int64_t>(f.height_hi_key)};
  t.all_max(maxima, 5);
  set_reduced_kernel<<<1, 1, 0, stream>>>(
      r_->state.get(), static_cast<uint32_t>(maxima[0]), static_cast<uint32_t>(maxima[1]),
      static_cast<unsigned long long>(maxima[2]), static_cast<uint32_t>(bad),
      kHeightLoReset - static_cast<uint32_t>(maxima[3]), static_cast<uint32_t>(maxima[4]));
  check_launch("set_reduced_kernel");
}

const uint32_t* CudaBackend::halo_apply_sinks(const PipelineSetup& setup, uint32_t sink_count, bool last,
                                              HostVector<uint32_t>& removed_ids,
                                              HostVector<uint32_t>& removed_by_sink) {
  const PipelineBuffers b = r_->buffers();
  const ParticleArrays& a = b.store->arrays();
  cudaStream_t s = r_->stream;
  // The frame's statistics read the last density pass's neighbour counts, in the sorted order the
  // ghosts' drop and the sinks' compaction change: counted for every particle, then carried along
  // (as the undivided stream driver does for its compaction).
  uint32_t* counts = nullptr;
  if (last) {
    counts = r_->sinks.counts();
    b.statistics->enqueue_neighbor_counts(setup.fluid, b.grid->view(), a, halo_owned_ + halo_ghosts_, counts,
                                          s);
  }
  halo_drop_ghosts(counts);
  const uint32_t n = halo_owned_;
  uint32_t* kept_out = r_->sink_kept.get();
  r_->sinks.enqueue_flag(r_->scene_buffer.sinks(), sink_count, a, n, b.state, s);
  cuda_check(cudaMemcpyAsync(kept_out, r_->sinks.kept_device(), sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
             "copy of the sink survivor count");
  cuda_check(cudaStreamSynchronize(s), "sinks");
  const uint32_t kept = *kept_out;
  if (kept == n) return counts;
  r_->sinks.enqueue_compact(*b.store, n, kept, counts, s);
  r_->sinks.take_removed(n - kept, removed_ids, removed_by_sink, s);
  halo_owned_ = kept;
  return counts;
}

uint32_t CudaBackend::run_frame_distributed(PipelineSetup setup, uint32_t sink_count,
                                            HostVector<uint32_t>& removed_ids,
                                            HostVector<uint32_t>& removed_by_sink,
                                            const StepInterrupt& interrupt, bool& interrupted) {
  const PipelineBuffers b = r_->buffers();
  cudaStream_t s = r_->stream;
  FrameState* out = b.state_output;
  halo_owned_ = count_;
  halo_ghosts_ = 0;
  // (Between frames the spring lists hold ids, also after a rolled-back frame: the snapshot's.)
  halo_springs_indexed_ = false;
  halo_linking_ = false;
  // A failure agreed at the frame's start rolls back to here: the snapshot and the step inputs
  // are taken before it (enqueue_frame_begin takes them again, after the reductions).
  b.store->enqueue_snapshot(count_, s);
  save_rollback_inputs_kernel<<<1, 1, 0, s>>>(b.state);
  check_launch("save_rollback_inputs_kernel");
  rollback_point_enqueued_ = true;
  halo_begin_frame(setup.limits);
  setup.count = count_;
  setup.ghosts = 0;
  enqueue_frame_begin(setup, b, LoopCondition{}, s, false);
  cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
             "copy of the loop condition");
  cuda_check(cudaStreamSynchronize(s), "frame begin");
  HaloHooks hooks(*this);
  const uint32_t* counts_after_sinks = nullptr;
  while (out->run) {
    halo_drop_ghosts();
    halo_gather();
    setup.count = halo_owned_ + halo_ghosts_;
    setup.ghosts = halo_ghosts_;
    // The lane groups as the undivided world picks them, from the world's count.
    if (tuning_.particle_lanes == 0)
      setup.tuning.particle_lanes = lanes_per_particle(
          tuning_, static_cast<uint32_t>(std::min<int64_t>(halo_world_count_, UINT32_MAX)));
    enqueue_substep(setup, b, LoopCondition{}, s, &hooks);
    setup.count = halo_owned_ + halo_ghosts_;  // (RK4: its last stage's halo)
    setup.ghosts = halo_ghosts_;
    cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
               "copy of the loop condition");
    cuda_check(
        cudaMemcpyAsync(&out->non_finite, &b.state->non_finite, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
        "copy of the non-finite flag");
    cuda_check(cudaStreamSynchronize(s), "substep");
    // A cancel or budget seen by any rank stops every rank at the same substep (after its sinks,
    // as on the CPU rank).
    const bool stop = out->run && halo_any(interrupt.requested());
    // Sinks (not after a failed substep, which every rank found in the substep's reduction).
    if (sink_count > 0 && !out->non_finite) {
      counts_after_sinks =
          halo_apply_sinks(setup, sink_count, !out->run || stop, removed_ids, removed_by_sink);
      setup.count = halo_owned_;
      setup.ghosts = 0;
    }
    if (stop) {
      interrupted = true;
      break;
    }
  }
  // (The statistics leave the last substep's ghosts out; with sinks they are gone already, and the
  // counts of its density pass came along.)
  enqueue_frame_end(setup, b, s, counts_after_sinks);
  halo_drop_ghosts();
  cuda_check(cudaStreamSynchronize(s), "frame end");
  // The loads' sum over the ranks before the frame's last agreement, as on the CPU rank: a rank
  // whose part of it fails (an allocation) rolls back with the others.
  if (setup.loads.on()) halo_sum_loads(setup.loads.output, setup.loads.colliders);
  halo_agree();  // (the frame's end: nothing after this can fail on one rank alone)
  return halo_owned_;
}

}  // namespace sph
