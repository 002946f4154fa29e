// SPDX-License-Identifier: MIT
// The CPU backend's per-particle passes of a substep: hash and sort, density and pressure (with
// the normalised density and the colour-field normals when on), and the acceleration gather
// with the world's options compiled in (the twin of cuda/substep_kernels.cu). The neighbour
// gathers run on the processor's SIMD target (cpu_simd_passes.h) and read the sorted records as
// columns, which these passes keep up to date next to the records.
#include "../physics/density.h"
#include "../physics/density_diffusion.h"
#include "../physics/density_normalization.h"
#include "../physics/dfsph_passes.h"
#include "../physics/force_fields.h"
#include "cpu_backend_impl.h"

namespace sph {

// Hash, sort, reorder every attribute, then density and pressure (packed into the w slots).
void CpuBackend::sort_and_density(const FluidConstants& fluid, const SceneFrame& scene, StageTime at,
                                  FrameReport& report, float diffusion_dt) {
  auto t = stage_start();
  if (rank_) rank_->gather();
  // (A rank times the grid, the reorder and the keys too: HaloPhaseTimes.)
  HaloPhaseTimes undivided;
  PhaseClock phases(rank_ ? rank_->phase_times() : undivided);
  grid_.build(position_.data(), count_, workers_, rank_ ? rank_->grid_shape() : nullptr,
              rank_ ? rank_->visit_order() : nullptr);
  phases.lap(kHaloGrid);
  columns_.resize(count_);
  // The columns copy each block of the new order as soon as it is reordered (data() is the new
  // order inside the reorder).
  store_.permute(grid_.order().data(), count_, parallel(), [this](size_t first, size_t last) {
    columns_.copy_state(position_.data(), velocity_.data(), first, last);
  });
  phases.lap(kHaloReorder);
  if (rank_) {
    rank_->after_sort(grid_);
    phases.lap(kHaloKeys);
  }
  end_stage(report, kStageHashSort, t);

  t = stage_start();
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  Float4* pos = position_.data();
  Float4* vel = velocity_.data();
  float* factor = density_factor_.data();
  Float4* boundary = boundary_.data();
  const ColliderView* colliders = collider_views_.data();
  const uint32_t collider_count = static_cast<uint32_t>(collider_views_.size());
  (void)scene;  // its colliders, with their maps bound, are collider_views_
  // A distributed world's ghosts (null otherwise): the density passes below skip them,
  // as the force pass does, since each publication ends with the ghosts taking their owners'
  // values (halo_share_density, halo_share_dfsph_density, halo_share_normals), and a ghost's own sums, over a
  // neighbourhood that is not complete on this rank, were only ever overwritten. (A sum reads its neighbours'
  // positions and published values alone, so the owned particles' bits do not change.)
  const uint32_t* halo = origins();
  // The walls' share at particle i (SPH_FEATURE_BOUNDARY_DENSITY), its record kept for the force
  // pass and DFSPH's solves; none without the feature.
  auto wall = [&](int i) {
    if (!boundary) return no_boundary_share();
    const BoundaryShare b =
        boundary_share(fluid.methods.boundary, colliders, collider_count, xyz(pos[i]), at.s, at.tau);
    boundary[i] = pack_boundary(b);
    return b;
  };
  if (config_.solver == Solver::Dfsph) {
    // DFSPH: the density and the factor alpha / rho in one walk (on the SIMD target); no equation
    // of state (w: the pressure, written when the density solve has found it). Its solves read
    // the columns' positions and write their velocities and pressures into the columns
    // (cpu_dfsph_solver.cpp).
    float* dfsph_factor = dfsph_factor_.data();
    parallel().for_each(count_, [&](uint32_t i) {
      if (halo && halo[i]) {  // a ghost: its owner's density, factor and count arrive below
        pos[i].w = 0.0f;      // (which the share writes into the column with them)
        return;
      }
      const DfsphDensitySample s = simd_.dfsph_density_and_factor(fluid, view, columns, wall(i), i);
      density_[i] = s.density;
      neighbors_[i] = s.neighbor_count;
      dfsph_factor[i] = s.factor;
      pos[i].w = 0.0f;
      vel[i].w = 1.0f / s.density;
      columns_.set_density(i, 0.0f, vel[i].w);
      columns_.set_neighbor_count(i, s.neighbor_count);
    });
    if (rank_) halo_share_dfsph_density();
  } else {
    parallel().for_each(count_, [&](uint32_t i) {
      if (halo && halo[i]) return;  // a ghost: its owner's values arrive below
      DensitySample s = simd_.density(fluid, view, columns, static_cast<uint32_t>(i));
      // The walls' share is part of the summation (and so of a normalised density's kernel sum).
      if (boundary) s.density += wall(i).density;
      float rho = s.density;
      if (factor) {
        normalized_[i] = s.density;  // the summation, for the factor after the filter
        rho = carried_density(fluid, s.density, factor[i]);
      }
      density_[i] = rho;
      neighbors_[i] = s.neighbor_count;
      // Only the w slots are written; neighbours read x, y, z alone.
      pos[i].w = pressure_from_density(fluid.methods.eos, rho);
      vel[i].w = 1.0f / rho;
      columns_.set_density(static_cast<uint32_t>(i), pos[i].w, vel[i].w);
      columns_.set_neighbor_count(static_cast<uint32_t>(i), s.neighbor_count);
    });
    if (rank_) halo_share_density();
  }
  // The Shepard filter, unless the density diffusion keeps the carried density instead
  // (density_diffusion.h says why one or the other).
  if (factor && !(config_.features & kFeatureDensityDiffusion)) {
    // Eq. 31 over every carried rho_j: each particle writes only its own factor and side
    // slot (the first pass is done reading the factors), then the filtered values are published.
    const float share =
        density_factor_relaxation(fluid.dt, speed_of_sound(fluid.methods.eos), fluid.kernel.h);
    parallel().for_each(count_, [&](uint32_t i) {
      if (halo && halo[i]) return;
      const FilteredDensity d =
          filtered_density(fluid, simd_.normalized_density(fluid, view, columns, static_cast<uint32_t>(i)),
                           normalized_[i], share);
      factor[i] = d.factor;
      normalized_[i] = d.density;
    });
    parallel().for_each(count_, [&](uint32_t i) {
      if (halo && halo[i]) return;
      density_[i] = normalized_[i];
      pos[i].w = pressure_from_density(fluid.methods.eos, normalized_[i]);
      vel[i].w = 1.0f / normalized_[i];
      columns_.set_density(static_cast<uint32_t>(i), pos[i].w, vel[i].w);
    });
    if (rank_) halo_share_density();  // the ghosts' filtered densities are their owners'
  }
  if (diffusion_dt > 0.0f) diffuse_density(fluid, diffusion_dt);
  if (config_.features & kFeatureSurfaceTension) {
    // Colour-field normals of every particle, which the force gather reads for neighbours.
    parallel().for_each(count_, [&](uint32_t i) {
      if (halo && halo[i]) return;
      normals_[i] = simd_.colour_normal(fluid, view, columns, static_cast<uint32_t>(i));
      columns_.set_normal(static_cast<uint32_t>(i), normals_[i]);
    });
    if (rank_) halo_share_normals();
  }
  end_stage(report, kStageDensity, t);
}

void CpuBackend::diffuse_density(const FluidConstants& fluid, float dt) {
  if (!(config_.features & kFeatureDensityDiffusion)) return;
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  Float4* pos = position_.data();
  Float4* vel = velocity_.data();
  float* factor = density_factor_.data();
  // The gather reads every published rho_j; each particle writes only its own factor and side
  // slot (free once the filtered densities are published), then the diffused values are published.
  const uint32_t* halo = origins();  // (the ghosts: as in sort_and_density)
  parallel().for_each(count_, [&](uint32_t i) {
    if (halo && halo[i]) return;
    const float rate = simd_.density_diffusion(fluid, view, columns, static_cast<uint32_t>(i));
    const DiffusedDensity d =
        diffused_density(fluid, fluid.methods.density_diffusion, density_[i], factor[i], rate, dt);
    factor[i] = d.factor;
    normalized_[i] = d.density;
  });
  parallel().for_each(count_, [&](uint32_t i) {
    if (halo && halo[i]) return;
    density_[i] = normalized_[i];
    pos[i].w = pressure_from_density(fluid.methods.eos, normalized_[i]);
    vel[i].w = 1.0f / normalized_[i];
    columns_.set_density(static_cast<uint32_t>(i), pos[i].w, vel[i].w);
  });
  if (rank_) halo_share_density();  // the ghosts' diffused densities are their owners'
}

// Acceleration of particle i: the neighbour gather with the world's force terms compiled in
// (forces.h, on the SIMD target), plus the scene's force fields.
Vec3 CpuBackend::acceleration(AccelerationFn gather, const FluidConstants& fluid, const GridView& view,
                              const NeighborColumns& columns, const SceneFrame& scene, uint32_t i) const {
  Vec3 a = gather(fluid, view, columns, i);
  const Vec3 x = xyz(position_[i]);
  for (const ForceFieldFrame& f : scene.fields) a += force_field_acceleration(f.view, x);
  return a;
}

// The scalar gather (forces.h) with or without the pressure force, plus the scene's force fields.
template <class Terms, bool kPressure>
Vec3 CpuBackend::acceleration_with(const FluidConstants& fluid, const GridView& view, const ForceInputs& in,
                                   const SceneFrame& scene, uint32_t i) {
  Vec3 a = gather_acceleration<Terms, kPressure>(fluid, view, in, i);
  for (const ForceFieldFrame& f : scene.fields) a += force_field_acceleration(f.view, xyz(in.positions[i]));
  return a;
}

CpuBackend::ScalarAccelerationFn CpuBackend::scalar_acceleration_function() const {
  const bool pressure = config_.solver == Solver::WeaklyCompressible;
  return with_force_terms(config_.selection(), [pressure](auto terms) -> ScalarAccelerationFn {
    return pressure ? &acceleration_with<decltype(terms), true> : &acceleration_with<decltype(terms), false>;
  });
}

ForceInputs CpuBackend::force_inputs() const {
  return ForceInputs{position_.data(), velocity_.data(), neighbors_.data(), normals_.data()};
}

}  // namespace sph
