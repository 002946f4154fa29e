// SPDX-License-Identifier: MIT
// The CPU backend's DFSPH substep (physics/dfsph.h; the twin of cuda/dfsph_solver.cu): density and
// factor, the divergence solve on the current velocities, the non-pressure accelerations into
// v*, the density solve on v*, then positions and colliders. Each solve is a Jacobi iteration of
// two passes, the velocity update (dfsph_correct) and the new rates and pressures
// (dfsph_residuals), until its errors are within their bounds (dfsph.h) or its cap; with
// SPH_DFSPH_CONJUGATE_GRADIENTS the density solve is cpu_dfsph_cg.cpp's instead. The mean is an exact
// sum (exact_float_sum.h), so it, the iteration count and every result depend on neither the
// thread count nor, in a distributed world, the ranks.
//
// The neighbour passes run on the processor's SIMD target (cpu_simd_passes.h: the factor pass in
// sort_and_density, the velocity updates, the rates and the non-pressure accelerations here) and
// read the columns: positions, the velocities each velocity update writes next to the records,
// the density pass's 1 / rho and counts, and the iteration's k in the pressure column.
//
// Loads and probes: the probes sample the substep's start once both solves have found its
// pressure; with SPH_FEATURE_COLLIDER_LOADS each contact clamp's velocity change is summed per
// particle (dfsph_clamp) and the loads pass adds it to the walls' reactions of both solves and
// the collision response's contacts (physics/collider_loads.h).
#include <algorithm>
#include <cmath>

#include "../core/dfsph_jacobi_loop.h"
#include "../core/exact_float_sum.h"
#include "cpu_backend_impl.h"

namespace sph {

void CpuBackend::dfsph_find_contacts(const SceneFrame& scene, const SubstepTime& time) {
  dfsph_colliders_.clear();
  for (const ColliderFrame& c : scene.colliders) dfsph_colliders_.push_back(c.view);
  dfsph_contacts_ = !dfsph_colliders_.empty();
  if (!dfsph_contacts_) return;
  const Float4* pos = position_.data();
  Float4* contact = dfsph_contact_.data();
  const ColliderView* views = dfsph_colliders_.data();
  const uint32_t count = static_cast<uint32_t>(dfsph_colliders_.size());
  const float h = config_.kernel_radius;
  // With the loads, each particle's clamp impulses start at zero, named after its contact's
  // collider (collider_loads.h).
  Float4* clamp = loads_on() ? clamp_impulse_.data() : nullptr;
  parallel().for_each(count_, [&](uint32_t i) {
    uint32_t collider = count;
    contact[i] = wall_contact(views, count, time, h, xyz(pos[i]), collider);
    if (clamp) clamp[i] = no_clamp(collider);
  });
}

void CpuBackend::dfsph_clamp(uint32_t i, Vec3& v) {
  const Vec3 held = respect_contact(dfsph_contact_[i], v);
  if (loads_on()) add_clamp(clamp_impulse_[i], v, held);
  v = held;
}

void CpuBackend::dfsph_correct(const FluidConstants& fluid, const DfsphWalls& walls, float dt, Float4* v,
                               float* carried, float carry_scale) {
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  const float* k = columns_.dfsph_step();
  const Float4* contact = dfsph_contacts_ ? dfsph_contact_.data() : nullptr;
  // SPH_DFSPH_CORRECTED_GRADIENT: the corrected gradient (physics/dfsph_gradient_correction.h).
  const SimdPasses::DfsphVelocityChangeFn change = fluid.methods.dfsph.gradient_correction
                                                       ? simd_.dfsph_velocity_change_corrected
                                                       : simd_.dfsph_velocity_change;
  // The gather reads positions and k; each particle writes only its own velocity (record and
  // column), which the next rate pass reads. A distributed rank's ghosts keep only their sums of
  // k (the conjugate gradients read them): their velocities are their owners', taken right after
  // every call (share_velocities), and their clamps count in no load.
  const uint32_t* halo = origins();
  parallel().for_each(count_, [&](uint32_t i) {
    if (halo && halo[i]) {
      carried[i] += k[i] * carry_scale;
      return;
    }
    Vec3 vi = xyz(v[i]) + change(fluid, view, columns, k, walls, i, dt);
    if (contact) dfsph_clamp(i, vi);
    v[i] = make_float4_record(vi, v[i].w);
    columns_.set_velocity(i, vi);
    carried[i] += k[i] * carry_scale;
  });
}

void CpuBackend::dfsph_residuals(DfsphSolve kind, const FluidConstants& fluid, const DfsphWalls& walls,
                                 float dt, DfsphChebyshevPass pass, const float* held) {
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  const float* factor = dfsph_factor_.data();
  const float* density = density_.data();
  const uint32_t* neighbors = neighbors_.data();
  float* k = columns_.dfsph_step();
  float* error = dfsph_residual_.data();
  const Dfsph::Constants& c = fluid.methods.dfsph;
  const float rho0 = fluid.rest_density;
  const SimdPasses::DfsphRateFn density_rate_of = simd_.dfsph_density_rate;
  // SPH_DFSPH_CHEBYSHEV (dfsph_chebyshev.h): the density solve's steps mixed with the last ones.
  const bool chebyshev = chebyshev_density_solve(c, kind == DfsphSolve::Divergence);
  // The gather reads positions and the velocities' columns; each particle writes only its k. A
  // distributed rank's ghosts are skipped: they take their owners' k right after (share_steps),
  // and the errors leave them out.
  const uint32_t* halo = origins();
  parallel().for_each(count_, [&](uint32_t i) {
    if (halo && halo[i]) return;
    const float rate = density_rate_of(fluid, view, columns, walls, i);
    if (chebyshev) {
      const DfsphResidual r =
          chebyshev_density_residual(rate, density[i], factor[i], rho0, dt, held[i], pass, &k[i]);
      k[i] = r.k;
      error[i] = r.error;
      return;
    }
    const DfsphResidual r = kind == DfsphSolve::Divergence
                                ? divergence_residual(c, rate, neighbors[i], factor[i], rho0, dt)
                                : density_residual(rate, density[i], factor[i], rho0, dt);
    k[i] = r.k;
    error[i] = r.error;
  });
}

DfsphErrors CpuBackend::dfsph_errors(DfsphSolve kind) {
  // Exact, so the mean is the same bits whichever particles a rank holds (exact_float_sum.h). The
  // largest only for the density solve, which bounds it (0 for the divergence solve, as on CUDA).
  const bool density = kind == DfsphSolve::Density;
  const float* error = dfsph_residual_.data();
  ExactFloatSum sum;
  float largest = 0.0f;
  for (uint32_t i = 0; i < count_; ++i)
    if (!ghost(i)) {
      sum.add(error[i]);
      if (density) largest = error[i] > largest ? error[i] : largest;
    }
  int64_t particles = count_;
  if (rank_) {
    rank_->agree();  // (the shares' buffers: a rank that failed there meets the others here)
    rank_->transport().all_sum(sum.terms(), ExactFloatSum::kTerms);
    if (density) rank_->transport().all_max(&largest, 1);
    particles = rank_->world_count();
  }
  return {particles > 0 ? static_cast<float>(sum.value() / static_cast<double>(particles)) : 0.0f, largest};
}

CpuBackend::SolveOutcome CpuBackend::dfsph_solve(DfsphSolve kind, const FluidConstants& fluid,
                                                 const DfsphWalls& walls, float dt, Float4* v, float* carried,
                                                 float carry_scale) {
  const Dfsph::Constants& c = fluid.methods.dfsph;
  if (c.linear_solver == kDfsphConjugateGradients && kind == DfsphSolve::Density)
    return dfsph_solve_cg(fluid, walls, dt, v, carried);
  const bool divergence = kind == DfsphSolve::Divergence;
  const DfsphBounds bounds = dfsph_solve_bounds(c, divergence, dt);
  const uint32_t min_iterations = divergence ? Dfsph::kMinDivergenceIterations : Dfsph::kMinIterations;
  const uint32_t max_iterations = divergence ? c.max_divergence_iterations : c.max_iterations;
  // The warm start: half the last substep's pressure, applied once; the solve's own
  // pressures add to it.
  float* k = columns_.dfsph_step();
  parallel().for_each(count_, [&](uint32_t i) {
    k[i] = Dfsph::kWarmStart * carried[i] / carry_scale;
    carried[i] = 0.0f;
  });
  // The loop and, on a rank, the ghosts' refreshes between its passes (core/dfsph_jacobi_loop.h).
  struct Passes {
    CpuBackend& b;
    DfsphSolve kind;
    const FluidConstants& fluid;
    const DfsphWalls& walls;
    float dt;
    Float4* v;
    float* carried;
    float carry_scale;
    uint32_t pass;              // the residual passes run so far
    DfsphChebyshevGuard guard;  // SPH_DFSPH_CHEBYSHEV's (dfsph_chebyshev.h), on the world's errors
    bool guarded;               // the guard applies: SPH_DFSPH_CHEBYSHEV's density solve
    DfsphBounds bounds;
    void velocity_update(bool) { b.dfsph_correct(fluid, walls, dt, v, carried, carry_scale); }
    void share_velocities() {
      if (b.rank_) b.halo_share_velocities(v);
    }
    void rates() {
      b.dfsph_residuals(kind, fluid, walls, dt, chebyshev_guarded_pass(guard, pass++), carried);
    }
    void share_steps() {
      if (b.rank_) b.halo_share_dfsph_step();
    }
    DfsphErrors errors() { return b.dfsph_errors(kind); }
    void checked(uint32_t iterations, const DfsphErrors& errors, bool) {
      if (guarded) chebyshev_guard_check(guard, iterations, errors.mean, bounds.mean);
    }
  } passes{*this,
           kind,
           fluid,
           walls,
           dt,
           v,
           carried,
           carry_scale,
           0u,
           DfsphChebyshevGuard{},
           chebyshev_density_solve(c, divergence),
           bounds};
  const DfsphLoopOutcome o = run_dfsph_jacobi(passes, bounds, min_iterations, max_iterations);
  return SolveOutcome{o.iterations, o.errors.mean, o.errors.largest, o.capped, passes.guard.plain != 0u};
}

uint32_t CpuBackend::substep_dfsph(const FluidConstants& fluid, const SceneFrame& scene,
                                   const SubstepTime& time, FrameReport& report, DfsphTallies& tallies) {
  sort_and_density(fluid, scene, stage_time(time, 0.0f), report);
  spring_pass(time.dt, true, report);
  auto t = stage_start();
  const float dt = time.dt;
  const DfsphWalls walls{boundary_.data()};  // the walls' share (dfsph_boundary.h), null without it
  dfsph_find_contacts(scene, time);
  // 2. The divergence solve corrects the current velocities in place (a failed frame restores
  // them from the snapshot).
  if (fluid.methods.dfsph.divergence_solve) {
    const SolveOutcome o =
        dfsph_solve(DfsphSolve::Divergence, fluid, walls, dt, velocity_.data(), dfsph_divergence_.data(), dt);
    record_solve(tallies.divergence, o.iterations, o.error, o.largest, o.capped, o.guarded);
  } else {
    std::fill(dfsph_divergence_.data(), dfsph_divergence_.data() + count_, 0.0f);  // no warm start to keep
  }
  // 3. The non-pressure accelerations: v* = v + dt a, into next_velocity_ (w: 1 / rho).
  const GridView view = grid_.view();
  const Float4* pos = position_.data();
  const Float4* vel = velocity_.data();
  Float4* next_pos = next_position_.data();
  Float4* next_vel = next_velocity_.data();
  const Float4* spring = spring_acceleration_.data();
  // The gather without the pressure force on the SIMD target, over the columns: the velocities
  // the divergence solve left (or the sorted ones without it), the density pass's 1 / rho.
  const AccelerationFn non_pressure = simd_.acceleration_without_pressure_for(config_.selection());
  const NeighborColumns columns = columns_.view();
  const Float4* contact = dfsph_contacts_ ? dfsph_contact_.data() : nullptr;
  const uint32_t* origin = origins();  // null unless distributed
  const float a2max = parallel().reduce(
      count_, 0.0f,
      [&](uint32_t i, float& m) {
        // A distributed world's ghost: its owner's acceleration counts, and its v* is its owner's,
        // shared after the density solve's first velocity update, which reads no ghost's v*.
        if (origin && origin[i]) return;
        Vec3 a = acceleration(non_pressure, fluid, view, columns, scene, i);
        if (spring) a += xyz(spring[i]);
        m = std::max(m, length_squared(a));
        Vec3 v = xyz(vel[i]) + a * dt;
        if (contact) dfsph_clamp(i, v);
        next_vel[i] = make_float4_record(v, vel[i].w);
      },
      [](float a, float b) { return std::max(a, b); });
  max_acceleration_ = std::sqrt(a2max);
  // 4. The density solve on v*.
  const SolveOutcome o =
      dfsph_solve(DfsphSolve::Density, fluid, walls, dt, next_vel, dfsph_pressure_.data(), 1.0f);
  record_solve(tallies.pressure, o.iterations, o.error, o.largest, o.capped, o.guarded);
  // 5. x += dt v*; w: the pressure both solves applied in this substep, p = (k + k_v) rho^2, also
  // the start's record's (the probes sample it there, at the positions the solves worked on).
  const float* k = dfsph_pressure_.data();
  const float* k_v = dfsph_divergence_.data();
  const float* density = density_.data();
  const float divergence = fluid.methods.dfsph.divergence_solve ? 1.0f / dt : 0.0f;
  Float4* start = position_.data();
  parallel().for_each(count_, [&](uint32_t i) {
    const float p = dfsph_pressure(k[i], k_v[i] * divergence, density[i]);
    start[i].w = p;
    next_pos[i] = make_float4_record(xyz(pos[i]) + xyz(next_vel[i]) * dt, p);
  });
  end_stage(report, kStageForces, t);
  sample_probes(scene, dt, report);
  if (loads_on()) {
    // The walls' reactions of both solves, the clamp's impulses, the collision response's contacts
    // (collider_loads.h).
    OldPositions old;
    old.records = pos;
    collide_with_loads(fluid, scene, time, stage_time(time, 0.0f), dt, old, report,
                       dfsph_contacts_ ? clamp_impulse_.data() : nullptr);
  } else {
    collide_from(scene, time, pos, report);
  }
  t = stage_start();
  float v2max = 0.0f;
  const uint32_t bad_index = scan_next_state(v2max);
  if (bad_index != kAllFinite) diagnose_non_finite(fluid, scene, -1, bad_index);
  const uint32_t bad = finish_substep(v2max, bad_index);
  end_stage(report, kStageIntegrate, t);
  return bad;
}

}  // namespace sph
