// SPDX-License-Identifier: MIT
// The CUDA backend's frame: the scene uploaded, the frame run by one of its drivers (the frame
// graph, or the stream), the report read back, and the rollback that puts the particles back
// when a substep fails (the twin of src/cpu/cpu_frame_loop.cpp).
#include <cstring>
#include <string>
#include <vector>

#include "../src/core/crowded_cell.h"
#include "../src/core/rank_agreement.h"
#include "cuda_backend_impl.h"

namespace sph {
namespace {

bool same_setup(const PipelineSetup& a, const PipelineSetup& b) {
  return a.count == b.count && a.integrator == b.integrator && a.max_substeps == b.max_substeps &&
         std::memcmp(&a.fluid, &b.fluid, sizeof a.fluid) == 0 &&
         std::memcmp(&a.limits, &b.limits, sizeof a.limits) == 0 &&
         a.tuning.density_block == b.tuning.density_block && a.tuning.force_block == b.tuning.force_block &&
         a.tuning.particle_lanes == b.tuning.particle_lanes &&
         a.options.surface_tension == b.options.surface_tension &&
         a.options.normalized_density == b.options.normalized_density &&
         a.options.density_diffusion == b.options.density_diffusion &&
         a.options.viscosity == b.options.viscosity && a.options.springs == b.options.springs &&
         a.options.dfsph == b.options.dfsph && a.options.boundary_density == b.options.boundary_density &&
         std::memcmp(&a.options.methods, &b.options.methods, sizeof a.options.methods) == 0 &&
         std::memcmp(&a.springs, &b.springs, sizeof a.springs) == 0 &&
         a.scene.colliders == b.scene.colliders && a.scene.fields == b.scene.fields &&
         a.scene.collider_count == b.scene.collider_count && a.scene.field_count == b.scene.field_count &&
         a.scene.kernel_radius == b.scene.kernel_radius && a.loads.partials == b.loads.partials &&
         a.loads.sums == b.loads.sums && a.loads.output == b.loads.output &&
         a.loads.colliders == b.loads.colliders && a.loads.generation == b.loads.generation &&
         a.probes.generation == b.probes.generation && a.probes.views == b.probes.views &&
         a.probes.points == b.probes.points && a.probes.sums == b.probes.sums &&
         a.probes.output == b.probes.output && a.probes.probe_count == b.probes.probe_count &&
         a.probes.point_count == b.probes.point_count &&
         std::memcmp(&a.probes.constants, &b.probes.constants, sizeof a.probes.constants) == 0;
}

}  // namespace

void CudaBackend::bind_frame_scene(const SceneFrame& scene_in, PipelineSetup& setup) {
  if (!scene_in.empty()) {
    SceneFrame scene = scene_in;
    r_->sdf_cache.begin_frame();
    bind_scene_views(scene, [&](const SdfAsset& a) { return r_->sdf_cache.bind(a, r_->stream); });
    r_->sdf_cache.end_frame();
    if (options_.boundary_density) {
      r_->boundary_maps.begin_frame();
      for (ColliderFrame& c : scene.colliders)
        c.view.boundary_map = r_->boundary_maps.bind(
            *c.sdf, c.view.sdf, config_.kernel_radius,
            BoundaryDensity::map_level(setup.fluid.methods.boundary, c.view.sign), r_->stream);
      r_->boundary_maps.end_frame();
    }
    setup.scene = r_->scene_buffer.upload(scene, config_.kernel_radius, r_->stream);
    if ((config_.features & kFeatureColliderLoads) && !scene.colliders.empty())
      setup.loads = r_->loads.reserve(static_cast<uint32_t>(scene.colliders.size()), config_.capacity);
    if (!scene_in.sinks.empty()) r_->sinks.reserve(config_.capacity, *r_->store);
    cuda_check(cudaStreamSynchronize(r_->stream), "upload of the scene");
  }
  if (!scene_in.probes.empty()) {
    ProbeConstants constants;
    constants.kernel = make_kernel_coefficients(config_.kernel_radius);
    constants.particle_mass = config_.particle_mass;
    constants.rest_density = config_.rest_density;
    setup.probes = r_->probes.upload(scene_in, constants, r_->stream);
  }
}

void CudaBackend::prepare_scene(const SceneFrame& scene, const RuntimeParams& params) {
  require_alive();
  DeviceGuard guard(device_);
  PipelineSetup setup;
  setup.fluid = make_fluid_constants(config_, params);
  guarded([&] {
    (void)cudaGetLastError();  // as at a frame's start (step_scene_frame)
    bind_frame_scene(scene, setup);
  });
}

// One frame, run by one of two drivers (docs/cuda.md): the frame graph (frame_graph.h), or the
// stream driver (run_frame_on_stream) for frames with sinks and when graphs are off. A frame
// with colliders and force fields runs in the frame graph like any other: the scene's assets
// and views are uploaded first, outside the graph.
FrameReport CudaBackend::step_scene_frame(double frame_dt, const RuntimeParams& params,
                                          const SceneFrame& scene_in) {
  require_alive();
  DeviceGuard guard(device_);
  PipelineSetup setup;
  setup.count = count_;
  setup.integrator = config_.integrator;
  setup.fluid = make_fluid_constants(config_, params);
  // Refused first when the parameters are set (capi/dfsph_solver_check.h); this holds for the paths
  // that reach the step otherwise, where the world also has no arrays for them (particle_arrays.cpp).
  // (A distributed rank runs them since session 16: dfsph_cg_rank_solver.cu's host-driven loop.)
  if (config_.solver == Solver::Dfsph &&
      setup.fluid.methods.dfsph.linear_solver == kDfsphConjugateGradients &&
      (config_.features & (kFeatureBoundaryDensity | kFeatureColliderLoads)))
    throw Error(Status::Unsupported,
                "step: DFSPH's conjugate gradients solve (sph_dfsph_params.linear_solver = "
                "SPH_DFSPH_CONJUGATE_GRADIENTS) does not work with SPH_FEATURE_BOUNDARY_DENSITY or "
                "SPH_FEATURE_COLLIDER_LOADS yet; use SPH_DFSPH_JACOBI");
  setup.limits = make_step_limits(config_, params);
  setup.max_substeps = params.stepping.max_substeps;
  setup.options = options_;
  setup.tuning = tuning_;
  if (options_.springs) setup.springs = setup.fluid.methods.springs;
  float frame_ms = 0.0f;
  const bool with_sinks = !scene_in.sinks.empty();
  uint32_t count_after = count_;
  HostVector<uint32_t> removed_ids, removed_by_sink(scene_in.sinks.size(), 0u);
  bool interrupted = false;  // the stream driver stopped at a substep boundary (StepInterrupt)
  rollback_point_enqueued_ = false;
  // The report's per-object sums are allocated before the frame: the host allocator (maybe the
  // engine's) can fail, and once the particles have moved nothing may.
  FrameReport report;
  if (config_.features & kFeatureColliderLoads)
    report.collider_loads.assign(scene_in.colliders.size(), ColliderLoadSums{});
  report.probes.assign(scene_in.probes.size(), ProbeSums{});
  try {
    guarded([&] {
      // An error left pending in the library's CUDA runtime by work that handled it would be read by
      // the frame's first launch check as the frame's own failure: cleared here (a sticky error
      // persists and is reported). The runtime is the library's own (cudart_static, private), so
      // a caller's CUDA calls cannot leave one; a program linking the static sph_internal can.
      (void)cudaGetLastError();
      bind_frame_scene(scene_in, setup);
      FrameInput* input = r_->input.get();
      input->frame_dt = frame_dt;
      input->max_collider_speed = scene_in.max_collider_speed;
      input->pad = 0;
      // A step budget needs the stream driver, which checks it between substeps (the graph
      // runs the whole frame on the device).
      // A distributed rank waits for the stream at its halo steps: the stream driver.
      const bool on_graph = use_graphs_ && !distributed() && !with_sinks &&
                            !scene_in.interrupt.has_deadline() && prepare_graph(setup);
      cuda_check(cudaEventRecord(r_->frame_start, r_->stream), "cudaEventRecord");
      if (on_graph) {
        r_->graph.launch(r_->stream);  // the snapshot is the graph's first work
        rollback_point_enqueued_ = true;
      } else if (distributed())
        count_after = run_frame_distributed(setup, static_cast<uint32_t>(scene_in.sinks.size()), removed_ids,
                                            removed_by_sink, scene_in.interrupt, interrupted);
      else
        count_after = run_frame_on_stream(setup, static_cast<uint32_t>(scene_in.sinks.size()), removed_ids,
                                          removed_by_sink, scene_in.interrupt, interrupted);
      cuda_check(cudaEventRecord(r_->frame_stop, r_->stream), "cudaEventRecord");
      if (scene_in.enqueued) scene_in.enqueued();  // e.g. a caller's stream waits for the frame
      cuda_check(cudaStreamSynchronize(r_->stream), "frame");
      cuda_check(cudaEventElapsedTime(&frame_ms, r_->frame_start, r_->frame_stop), "cudaEventElapsedTime");
    });
  } catch (const Error& e) {
    // A failure in the middle of a frame that did not lose the device (a host allocation
    // for the removed ids, say): the substeps already run are undone from the frame's
    // snapshot, so the failed step changes nothing.
    if (rollback_point_enqueued_ && e.status() != Status::DeviceLost) roll_back_frame();
    throw;
  } catch (const std::exception&) {
    if (rollback_point_enqueued_) roll_back_frame();
    throw;
  }
  const FrameState s = *r_->state_output.get();
  ++epoch_;
  // A non-finite particle first: its NaN position hashes into one cell with every other NaN,
  // so a frame that went non-finite can also report that cell as crowded (RK4's next stage
  // sorts the NaN positions), and the cause is the non-finite value, as the CPU reports it.
  // A crowded cell alone also raises non_finite (to stop the sinks) but records no bad
  // particle: bad_substep stays 0 (end_substep_kernel, frame_control.cu).
  if (s.non_finite && s.bad_substep != 0) {
    roll_back_frame();
    NonFiniteFailure failure;
    failure.stage = s.bad_stage;
    failure.substep = s.bad_substep;
    failure.dt = s.bad_dt;
    failure.count = s.bad_count;
    failure.ids.push_back(s.bad_id);  // the first; the device keeps no other ids
    if (distributed()) throw AgreedRankFailure(Status::NonFinite, non_finite_message(failure, setup.limits));
    throw Error(Status::NonFinite, non_finite_message(failure, setup.limits));
  }
  if (s.crowded_key != 0) {
    roll_back_frame();
    const Vec3 where{s.crowded_where[0], s.crowded_where[1], s.crowded_where[2]};
    const std::string message =
        crowded_cell_message(static_cast<uint32_t>(s.crowded_key >> 32), where,
                             max_particles_per_cell(config_.particle_spacing, config_.kernel_radius));
    // (Every rank of a distributed world found it in the substep's reduction: no agreement left.)
    if (distributed()) throw AgreedRankFailure(Status::Capacity, message);
    throw Error(Status::Capacity, message);
  }
  count_ = count_after;
  report.removed_ids = std::move(removed_ids);
  report.removed_by_sink = std::move(removed_by_sink);
  // Every collider has its sums (allocated above), zero for a frame without colliders' loads.
  if ((config_.features & kFeatureColliderLoads) && setup.loads.on())
    for (uint32_t c = 0; c < setup.loads.colliders; ++c) report.collider_loads[c] = setup.loads.output[c];
  for (uint32_t k = 0; k < setup.probes.probe_count; ++k) report.probes[k] = setup.probes.output[k];
  report_clock(s.clock, report);
  report.interrupted = interrupted;
  report.max_speed = s.max_speed;
  report_density(s.density, report);
  report.pressure_solve = finish_solve(s.pressure_tally);
  report.divergence_solve = finish_solve(s.divergence_tally);
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

// Restores the particles (and the cached max speed) from the snapshot taken at the start of
// the frame; count_ is still the count before the frame.
void CudaBackend::roll_back_frame() {
  ++epoch_;
  guarded([&] {
    r_->store->enqueue_restore(count_, r_->stream);
    enqueue_restore_max_speed(r_->state.get(), r_->stream);
    cuda_check(cudaStreamSynchronize(r_->stream), "rollback");
  });
}

// (Re)captures the frame graph when the particle count or a parameter changed. A graph that
// cannot be built for a non-sticky reason (an old driver without conditional nodes) leaves
// the world on the stream driver for good; returns whether the graph is ready.
bool CudaBackend::prepare_graph(const PipelineSetup& setup) {
  if (r_->graph.ready() && same_setup(setup, r_->graph_setup)) return true;
  try {
    r_->graph.build(setup, r_->buffers(), r_->stream);
    r_->graph_setup = setup;
    return true;
  } catch (const Error& e) {
    if (e.status() == Status::DeviceLost || e.status() == Status::OutOfDeviceMemory) throw;
    use_graphs_ = false;
    return false;
  }
}

// The stream driver: the frame's work launched stage by stage on the stream, reading the loop
// condition back after every substep. It runs what the frame graph cannot: every frame with
// sinks (their compaction changes the particle count inside the frame, and a captured graph
// has its launch sizes fixed), and every frame when graphs are off or the driver cannot build
// them. With sinks, the survivor count comes back with the loop condition (one synchronisation
// per substep, a second one only when particles were removed). Returns the particle count after
// the frame; the removed ids, in the CPU backend's order, and the per-sink counts are appended.
// `interrupt` is checked after every substep that removed no particle (so the statistics read
// what a frame's natural end leaves); when it stops the frame, `interrupted` is set.
uint32_t CudaBackend::run_frame_on_stream(PipelineSetup setup, uint32_t sink_count,
                                          HostVector<uint32_t>& removed_ids,
                                          HostVector<uint32_t>& removed_by_sink,
                                          const StepInterrupt& interrupt, bool& interrupted) {
  const PipelineBuffers b = r_->buffers();
  const ParticleArrays& a = b.store->arrays();
  cudaStream_t s = r_->stream;
  FrameState* out = b.state_output;
  uint32_t* kept_out = r_->sink_kept.get();
  uint32_t n = count_;
  setup.count = n;
  enqueue_frame_begin(setup, b, LoopCondition{}, s);
  rollback_point_enqueued_ = true;  // (nothing before it touches a particle)
  cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
             "copy of the loop condition");
  cuda_check(cudaStreamSynchronize(s), "frame begin");
  const uint32_t* counts_after_sinks = nullptr;
  while (out->run) {
    setup.count = n;
    enqueue_substep(setup, b, LoopCondition{}, s);
    if (sink_count > 0) r_->sinks.enqueue_flag(r_->scene_buffer.sinks(), sink_count, a, n, b.state, s);
    cuda_check(cudaMemcpyAsync(&out->run, &b.state->run, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
               "copy of the loop condition");
    if (sink_count > 0) {
      cuda_check(cudaMemcpyAsync(&out->non_finite, &b.state->non_finite, sizeof(uint32_t),
                                 cudaMemcpyDeviceToHost, s),
                 "copy of the non-finite flag");
      cuda_check(
          cudaMemcpyAsync(kept_out, r_->sinks.kept_device(), sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
          "copy of the sink survivor count");
    }
    cuda_check(cudaStreamSynchronize(s), "substep");
    const auto stop_here = [&] { return out->run && (interrupted = interrupt.requested()); };
    if (sink_count == 0) {
      if (stop_here()) break;
      continue;
    }
    counts_after_sinks = nullptr;
    if (out->non_finite) break;  // as on the CPU: no sinks after a failed substep
    const uint32_t kept = *kept_out;
    if (kept == n) {
      if (stop_here()) break;
      continue;
    }
    // After the last substep the statistics need the neighbour counts of its density pass,
    // which the compaction carries along (the sorted copy it reads becomes scratch).
    uint32_t* counts = nullptr;
    if (!out->run) {
      counts = r_->sinks.counts();
      b.statistics->enqueue_neighbor_counts(setup.fluid, b.grid->view(), a, n, counts, s);
    }
    r_->sinks.enqueue_compact(*b.store, n, kept, counts, s);
    r_->sinks.take_removed(n - kept, removed_ids, removed_by_sink, s);
    n = kept;
    counts_after_sinks = counts;
  }
  setup.count = n;
  enqueue_frame_end(setup, b, s, counts_after_sinks);
  return n;
}

}  // namespace sph
