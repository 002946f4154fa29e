// SPDX-License-Identifier: MIT
// The CPU backend's class, shared by the files of src/cpu/ that implement it (one per stage of a
// frame, each the twin of a file of cuda/; see docs/architecture.md). Each substep sorts
// particles into the wrapped grid, then loops the shared per-particle physics (src/physics) over
// all particles on OpenMP threads or the engine's task system (cpu_parallel.h), the neighbour
// gathers on SIMD lanes (cpu_simd_passes.h). Results do not depend on the thread count, the
// task system nor the processor's SIMD target: every particle is a pure gather whose order of
// sums is fixed, and reductions are combined per block in block order. The loops hand out
// particles in blocks on demand, so a core that something else keeps busy holds up only the
// block it is working on.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "../core/backend.h"
#include "../core/non_finite.h"
#include "../core/particle_arrays.h"
#include "../core/slab_decomposition.h"
#include "../core/solver_record.h"
#include "../physics/collider_loads.h"
#include "../physics/dfsph_chebyshev.h"
#include "../physics/dfsph_passes.h"
#include "../physics/forces.h"
#include "../physics/integrate.h"
#include "../physics/probe_sampling.h"
#include "../physics/springs.h"
#include "cpu_boundary_maps.h"
#include "cpu_id_table.h"
#include "cpu_neighbor_columns.h"
#include "cpu_neighbor_grid.h"
#include "cpu_parallel.h"
#include "cpu_particle_store.h"
#include "cpu_rank_halo.h"
#include "cpu_simd_passes.h"
#include "cpu_stage_timing.h"

namespace sph {

class ExactFloatSum;

class CpuBackend final : public Backend {
 public:
  CpuBackend(const WorldConfig& config, unsigned workers, const TaskSystem& tasks);

  uint32_t particle_count() const override { return count_; }

  void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id,
              uint32_t user_attribute) override;

  FrameReport step_scene_frame(double frame_dt, const RuntimeParams& params,
                               const SceneFrame& scene_in) override;
  // The boundary-density maps of the scene's assets (computed on the workers when new or stale),
  // as a frame binds them.
  void prepare_scene(const SceneFrame& scene, const RuntimeParams& params) override;

  void truncate(uint32_t count) override;
  // The host arrays grow with the particles (append), so a new capacity is only a new limit.
  void reserve(uint32_t capacity, const GrowthNeeds&) override { config_.capacity = capacity; }

  void save_step_inputs() override {
    saved_inputs_ = StepInputs{max_speed_, max_acceleration_, max_speed_valid_,
                               link_from_ ? link_from_[0] : kNoPendingLinks};
  }
  void restore_step_inputs() override {
    max_speed_ = saved_inputs_.max_speed;
    max_acceleration_ = saved_inputs_.max_acceleration;
    max_speed_valid_ = saved_inputs_.max_speed_valid;
    if (link_from_) link_from_[0] = saved_inputs_.link_from;
  }

  void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                      size_t stride) const override;

  ParticleSnapshot export_particles() const override;

  void import_particles(const ParticleSnapshot& s) override;

  // Distributed worlds (cpu_halo.cpp).
  void attach_ranks(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options) override;
  const RankTransport* rank_transport() const override { return rank_ ? &rank_->transport() : nullptr; }
  const HaloPhaseTimes* halo_phase_times() const override { return rank_ ? &rank_->phase_times() : nullptr; }
  DistributedCounters distributed_counters() const override;
  std::shared_ptr<const RankTransport> shared_rank_transport() const override {
    return rank_ ? rank_->shared_transport() : nullptr;
  }
  DistributedState distributed_state() const override;
  void restore_distributed_state(const DistributedState& state) override;
  void rethrow_step_failure() const override;

  void adopt_asset_caches(Backend& previous) noexcept override {
    if (auto* p = dynamic_cast<CpuBackend*>(&previous)) boundary_maps_ = std::move(p->boundary_maps_);
  }

  uint64_t memory_bytes() const override {
    return store_.bytes() + grid_.bytes() + columns_.bytes() + boundary_maps_.bytes();
  }

 private:
  static constexpr uint32_t kAllFinite = 0xffffffffu;

  // The workers of a loop over the particles: small worlds run on the calling thread alone, where
  // waking a team (and its spinning idle threads) would cost more than the work.
  CpuParallel parallel() const { return workers_.for_items(count_); }

  int n() const { return static_cast<int>(count_); }

  float compute_max_speed() const;
  // DFSPH's depth limit (step_control.h): the lowest and highest x . g/|g| of the particles
  // held, under frame_limits_ (lo > hi when none is held).
  struct HeightSpan {
    float lo = INFINITY, hi = -INFINITY;
  };
  HeightSpan measure_height_span() const;
  bool depth_limit_on() const { return frame_limits_.depth_step_factor > 0.0f; }
  // This rank's span (an empty one where the limit is off).
  HeightSpan own_height_span() const { return depth_limit_on() ? measure_height_span() : HeightSpan{}; }
  // fluid_height_ from this rank's particles alone (an undivided world's; 0 where the limit is off).
  void measure_fluid_height() {
    const HeightSpan span = own_height_span();
    fluid_height_ = height_of_span(span.lo, span.hi);
  }

  // Hash, sort, reorder every attribute, then density and pressure (packed into the w slots).
  // With SPH_FEATURE_BOUNDARY_DENSITY the colliders' share joins the density, their poses at
  // the stage's time `at`.
  // With SPH_FEATURE_DENSITY_DIFFUSION and diffusion_dt > 0 the diffusion (diffuse_density)
  // follows the normalised density, before the colour-field normals.
  void sort_and_density(const FluidConstants& fluid, const SceneFrame& scene, StageTime at,
                        FrameReport& report, float diffusion_dt = 0.0f);

  // SPH_FEATURE_DENSITY_DIFFUSION (density_diffusion.h): the delta-SPH term over the published
  // densities, applied for dt through the carried factors and republished. Once per substep,
  // after its first density pass (sort_and_density calls it); nothing without the feature.
  void diffuse_density(const FluidConstants& fluid, float dt);

  // Binds the world's boundary-density maps into the scene's collider views (computing those
  // that are new or stale) and lists the views for the density pass.
  void bind_boundary_maps(const FluidConstants& fluid, SceneFrame& scene);

  // The wall's pressure acceleration of particle i (zero without SPH_FEATURE_BOUNDARY_DENSITY).
  Vec3 wall_acceleration(uint32_t i) const {
    return boundary_ ? boundary_pressure_acceleration(boundary_[i], position_[i].w, velocity_[i].w)
                     : Vec3{0.0f, 0.0f, 0.0f};
  }

  // The neighbour gather of the world's force terms (with_force_terms) on the SIMD target.
  using AccelerationFn = SimdPasses::AccelerationFn;
  AccelerationFn acceleration_function() const { return simd_.acceleration_for(config_.selection()); }
  // Acceleration of particle i: the neighbour gather plus the scene's force fields.
  Vec3 acceleration(AccelerationFn gather, const FluidConstants& fluid, const GridView& view,
                    const NeighborColumns& columns, const SceneFrame& scene, uint32_t i) const;
  // DFSPH's non-pressure accelerations: the scalar gather (forces.h) without the pressure force,
  // plus the scene's force fields. (The SIMD passes gather the weakly compressible scheme's
  // terms; DFSPH's pressure comes from its solves.)
  template <class Terms, bool kPressure>
  static Vec3 acceleration_with(const FluidConstants& fluid, const GridView& view, const ForceInputs& in,
                                const SceneFrame& scene, uint32_t i);
  using ScalarAccelerationFn = Vec3 (*)(const FluidConstants&, const GridView&, const ForceInputs&,
                                        const SceneFrame&, uint32_t);
  ScalarAccelerationFn scalar_acceleration_function() const;
  // The arrays the scalar force gather reads (normals and counts only where a term reads them).
  ForceInputs force_inputs() const;

  // Resolves colliders for the state in next_position_/next_velocity_, moved from x_old(i).
  template <class OldPosition>
  void collide(const SceneFrame& scene, const SubstepTime& time, OldPosition&& x_old, FrameReport& report);
  // The same from the positions `old` (xyz), for the files that do not see the template.
  void collide_from(const SceneFrame& scene, const SubstepTime& time, const Float4* old, FrameReport& report);

  // Loads (SPH_FEATURE_COLLIDER_LOADS, cpu_collider_loads.cpp): the frame's sums start at zero.
  void begin_loads(const SceneFrame& scene);
  bool loads_on() const { return (config_.features & kFeatureColliderLoads) != 0; }
  // Where a substep's particles started, for the collision response: one of the two (none: no
  // collision response in this pass).
  struct OldPositions {
    const Float4* records = nullptr;
    const ParticleState* states = nullptr;
  };
  // One force evaluation's loads: the walls' pressure reactions (boundary density) over
  // wall_seconds (its share of the substep; 0: none) at the stage's time `at`, then, when `old`
  // names the start positions, the collision response of the state in next_* with its contact
  // impulses. Adds to load_sums_. The walls' reactions read p (w of the start's records) and 1 / rho
  // (w of the velocities'). clamp: DFSPH's contact clamp impulses (kArrayDfsphContactImpulse), or
  // null.
  void collide_with_loads(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                          StageTime at, float wall_seconds, OldPositions old, FrameReport& report,
                          const Float4* clamp = nullptr);

  // Probes and gauges (cpu_probes.cpp; physics/probe_sampling.h): each sample point's sums over
  // the sorted particles of the density pass just run, then each probe's sample in point order,
  // weighted by the substep's dt into probe_sums_. No-op without probes.
  void begin_probes(const SceneFrame& scene);
  void sample_probes(const SceneFrame& scene, float dt, FrameReport& report);

  // Max speed and the first non-finite particle of the state in next_*.
  uint32_t scan_next_state(float& v2max) const;

  // Fills non_finite_ for the first non-finite particle of the state in next_* (the failure path).
  void diagnose_non_finite(const FluidConstants& fluid, const SceneFrame& scene, int rk4_stage,
                           uint32_t first);

  uint32_t finish_substep(float v2max, uint32_t bad_index);

  uint32_t substep_euler(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                         FrameReport& report);

  uint32_t substep_rk4(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                       FrameReport& report);

  // DFSPH's substep (cpu_dfsph_solver.cpp; physics/dfsph.h): density and factor, the divergence
  // solve, the non-pressure accelerations, the density solve, positions, colliders. The two
  // solves add to the frame's tallies.
  struct DfsphTallies {
    SolveTally pressure = empty_solve_tally();
    SolveTally divergence = empty_solve_tally();
  };
  uint32_t substep_dfsph(const FluidConstants& fluid, const SceneFrame& scene, const SubstepTime& time,
                         FrameReport& report, DfsphTallies& tallies);
  enum class DfsphSolve { Divergence, Density };
  struct SolveOutcome {
    uint32_t iterations;
    float error;    // the mean
    float largest;  // the largest particle error
    bool capped;
    bool guarded;  // the Chebyshev density solve's guard turned it to plain steps
  };
  // One solve over the velocities v (xyz; w: 1 / rho), from the warm start in `carried` (k,
  // times carry_scale: dt for the divergence solve's impulse, 1 for the density solve's
  // pressure), which it replaces with its own.
  SolveOutcome dfsph_solve(DfsphSolve kind, const FluidConstants& fluid, const DfsphWalls& walls, float dt,
                           Float4* v, float* carried, float carry_scale);
  // Each particle's contact with the scene's colliders (dfsph_contact_), for the solves.
  void dfsph_find_contacts(const SceneFrame& scene, const SubstepTime& time);
  // Holds v to particle i's contact (respect_contact); with the loads, adds the change to its
  // clamp impulses (clamp_impulse_).
  void dfsph_clamp(uint32_t i, Vec3& v);
  // Applies the iteration's pressures (columns_.dfsph_step()) to v (records and columns) and adds
  // them (times carry_scale) to carried.
  void dfsph_correct(const FluidConstants& fluid, const DfsphWalls& walls, float dt, Float4* v,
                     float* carried, float carry_scale);
  // New pressures and errors from the rates over the velocities the last dfsph_correct wrote (the
  // columns); the errors over the world's particles (the mean summed over the ranks, the largest
  // the ranks' largest). `pass`: the pass's Chebyshev weight or its guard's plain step
  // (chebyshev_guarded_pass), and `held` the solve's pressure so far (its carried array), for the
  // Chebyshev density solve (SPH_DFSPH_CHEBYSHEV; the other solves ignore both).
  void dfsph_residuals(DfsphSolve kind, const FluidConstants& fluid, const DfsphWalls& walls, float dt,
                       DfsphChebyshevPass pass, const float* held);
  DfsphErrors dfsph_errors(DfsphSolve kind);
  // The density solve by conjugate gradients (cpu_dfsph_cg.cpp; sph_dfsph_params.linear_solver);
  // its rate pass (each particle's value into cg_value_; returns the mean and largest error); a contact held
  // within an iteration (v_i changed by dv): the values of i and its neighbours.
  SolveOutcome dfsph_solve_cg(const FluidConstants& fluid, const DfsphWalls& walls, float dt, Float4* v,
                              float* carried);
  DfsphErrors dfsph_cg_measure(const FluidConstants& fluid, const DfsphWalls& walls, float dt);
  void dfsph_cg_hold_contact(const FluidConstants& fluid, const DfsphWalls& walls, float dt, uint32_t i,
                             Vec3 dv);
  // The world's sums and maxima from a rank's (the exact sums' bins added over the ranks, at most
  // three; the maxima the ranks' largest), after an agreement; nothing undivided. The particles
  // the solve's means divide by: the world's.
  void dfsph_cg_world(ExactFloatSum* sums, int n_sums, float* maxima, int n_maxima);
  int64_t dfsph_cg_particles() const;

  // Springs (SPH_FEATURE_SPRINGS), after the sort: the particles that wait for springs make
  // them (two passes, springs.h), then every particle gathers its spring acceleration into a
  // side array that the force pass adds. first_evaluation: the substep's first force
  // evaluation, where the rest lengths flow (plasticity).
  void spring_pass(float dt, bool first_evaluation, FrameReport& report);

  // Removes particles inside any sink, keeping the order of the rest; records their ids.
  void apply_sinks(const SceneFrame& scene, FrameReport& report);

  // Density and neighbour statistics of the last density evaluation.
  void summarize(FrameReport& report) const;

  // A stage's timing (cpu_stage_timing.h: on a rank, with the transport's share of it).
  StageStart stage_start() const { return start_stage(rank_ ? &rank_->transport() : nullptr); }
  void end_stage(FrameReport& report, StageIndex stage, const StageStart& start) const {
    sph::end_stage(report, stage, start, rank_ ? &rank_->transport() : nullptr);
  }

  // ---- a distributed world's rank (cpu_halo.cpp; include/sph_mpi.h): its halo steps and the
  // state they own are rank_'s (cpu_rank_halo.h). The backend's side, each step collective:
  // which of its values the ghosts take, and the step's inputs over the ranks.
  // A ghost of this substep (never in a world that is not distributed).
  bool ghost(uint32_t i) const { return rank_ && rank_->ghost(i); }
  // Each particle's origin (CpuRankHalo::origins; null in an undivided world).
  const uint32_t* origins() const { return rank_ ? rank_->origins() : nullptr; }
  // The frame's start: the world's max speed, and new slabs when the ranks are out of balance.
  void halo_begin_frame();
  // The maxima and the height span over the ranks.
  void reduce_step_inputs(const HeightSpan& span);
  // After the density pass: the ghosts take their owners' densities and pressures; after the
  // colour-field pass (surface tension), their normals.
  void halo_share_density();
  void halo_share_normals();
  // DFSPH (cpu_halo_solvers.cpp): the ghosts' density, factor and neighbour count after the
  // density pass, their velocities v after each velocity update, their pressure steps after each
  // rate pass (the conjugate gradients' solve: v, its search directions p in the steps' column and
  // its velocity steps dv_p in `v`; `what` names them in an error).
  void halo_share_dfsph_density();
  void halo_share_velocities(Float4* v, const char* what = "DFSPH velocities");
  void halo_share_dfsph_step();
  // The substep's end: ghosts dropped, the step size's inputs and any failure agreed by all
  // ranks. Returns the world's first non-finite particle id (kAllFinite: none).
  uint32_t halo_end_substep(uint32_t bad_id);

  WorldConfig config_;
  CpuParallel workers_;  // OpenMP's, or the engine's task system (cpu_parallel.h)
  CpuNeighborGrid grid_;
  const SimdPasses& simd_;      // the processor's SIMD target
  CpuNeighborColumns columns_;  // the sorted records as columns, for the SIMD passes
  CpuParticleStore store_;
  std::vector<ParticleArraySpec> method_arrays_;  // method_particle_arrays(config_)
  CpuArrayRef<Float4> position_;                  // w: pressure after the density pass
  CpuArrayRef<Float4> velocity_;                  // w: 1 / density after the density pass
  CpuArrayRef<uint32_t> id_;
  CpuArrayRef<float> density_;
  CpuArrayRef<uint32_t> neighbors_;  // of the last density pass (statistics, Clavet viscosity)
  // Integration writes here and swaps, so the force gather reads a state nobody writes.
  CpuArrayRef<Float4> next_position_;
  CpuArrayRef<Float4> next_velocity_;
  // The methods' arrays (particle_arrays.h); null when the world does not use the method.
  CpuArrayRef<ParticleState> rk4_start_;
  CpuArrayRef<Rk4Accumulator> rk4_sum_;
  CpuArrayRef<float> density_factor_;  // normalised density's carried factor
  CpuArrayRef<float> normalized_;      // normalised density: the summation, then eq. 31
  CpuArrayRef<Float4> normals_;        // colour-field normals (surface tension)
  CpuArrayRef<SpringList> springs_;    // springs: the lists, their link candidates, the accelerations
  CpuArrayRef<uint32_t> link_from_;    // one word: the lowest id that waits for its springs
  CpuArrayRef<uint32_t> spring_candidates_;
  CpuArrayRef<Float4> spring_acceleration_;
  CpuArrayRef<float> dfsph_pressure_;         // DFSPH: the density solve's p / rho^2 (warm start)
  CpuArrayRef<float> dfsph_divergence_;       // DFSPH: the divergence solve's p / rho^2 times dt
  CpuArrayRef<float> dfsph_factor_;           // DFSPH: alpha / rho of the density pass
  CpuArrayRef<float> dfsph_residual_;         // DFSPH: each particle's share of the solve's error
  CpuArrayRef<Float4> dfsph_contact_;         // DFSPH: each particle's contact with the colliders
  CpuArrayRef<Float4> clamp_impulse_;         // DFSPH with the loads: the clamp's, per particle
  bool dfsph_contacts_ = false;               // DFSPH: the substep has colliders (contacts to respect)
  HostVector<ColliderView> dfsph_colliders_;  // DFSPH: the substep's colliders, for the contacts
  CpuArrayRef<float> cg_value_;               // DFSPH by conjugate gradients: rho* - rho0 per particle
  CpuArrayRef<float> cg_change_;              // ... its change along the search direction
  CpuArrayRef<Float4> cg_velocity_step_;      // ... the velocity change of the search direction
  CpuArrayRef<uint8_t> cg_state_;             // ... in the active set; contact binds
  CpuArrayRef<Float4> boundary_;              // boundary density: (grad rho_b, v_b . grad rho_b) per particle
  CpuArrayRef<uint32_t> user_attribute_;      // SPH_FEATURE_USER_ATTRIBUTE: the caller's value
  CpuBoundaryMaps boundary_maps_;
  HostVector<ColliderView> collider_views_;  // the frame's colliders, for the density pass
  HostVector<ColliderLoadSums> load_sums_;   // the frame's impulses per collider (loads on)
  HostVector<LoadImpulse> load_blocks_;      // per block of kLoadBlock particles and collider
  HostVector<Vec3> load_points_;             // per collider: at the wall pass's time, at the end
  HostVector<ProbeGather> probe_points_;     // per sample point of the frame's probes
  HostVector<ProbeSums> probe_sums_;         // per probe: the frame's samples
  HostVector<uint32_t> keep_order_;          // apply_sinks, the rank's halo: the particles that stay
  // The three maxima an integration pass reduces, and the first non-finite particle.
  struct StateScan {
    float a2max = 0.0f, v2max = 0.0f;
    uint32_t bad_index = kAllFinite;
  };
  static StateScan combine_scans(StateScan a, const StateScan& b) {
    a.a2max = std::max(a.a2max, b.a2max);
    a.v2max = std::max(a.v2max, b.v2max);
    a.bad_index = std::min(a.bad_index, b.bad_index);
    return a;
  }
  SpringConstants spring_constants_{};
  uint32_t count_ = 0;
  float max_speed_ = 0.0f;
  float max_acceleration_ = 0.0f;  // of the last force evaluation, for the force step limit
  // The frame's step limits, and H of the depth limit for the next step (0: off): measured at the
  // frame's start and after each substep, before its sinks (a distributed world's ranks reduce it
  // with the maxima in halo_begin_frame and halo_end_substep), so nothing about it is saved or
  // restored.
  StepLimits frame_limits_{};
  float fluid_height_ = 0.0f;
  NonFiniteFailure non_finite_;  // of the last failed substep, for its error message
  bool max_speed_valid_ = false;
  struct StepInputs {
    float max_speed = 0.0f, max_acceleration = 0.0f;
    bool max_speed_valid = false;
    // The springs' lowest waiting id: an emission lowers it to the emitted particles' first id,
    // and a step that then fails must not leave it there (the world's checkpoint would differ).
    uint32_t link_from = kNoPendingLinks;
  } saved_inputs_;  // save_step_inputs()
  // A distributed world's rank, null in an undivided world. Declared last: it refers to the
  // store, the count and the workers above.
  std::unique_ptr<CpuRankHalo> rank_;
};

}  // namespace sph
