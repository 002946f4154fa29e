// SPDX-License-Identifier: MIT
// The CPU backend's DFSPH density solve by Jacobi-preconditioned conjugate gradients
// (sph_dfsph_params.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS; physics/dfsph_cg.h has the
// method and why the system is symmetric). Each iteration is one velocity update with the search
// direction as k and one rate pass over the velocities it would give, as a Jacobi iteration's
// two passes. Every sum is exact (exact_float_sum.h) and taken in storage order, and the
// contacts are held in storage order, so no result depends on the worker count.
//
// On a rank of a distributed world (docs/distributed.md) the neighbour passes run over the rank's
// own particles and skip its ghosts, whose results there (over an incomplete neighbourhood) would
// only be replaced by their owners': the ghosts take their owners' velocities after the warm
// start's update, their search directions p before each velocity update of p, and their velocity
// steps dv_p after it (the rate pass reads them). Everything else a ghost holds follows from these
// as its owner's does (v, the carried pressure, the contact holds, which depend on the particle's
// own velocity alone, and which the ghosts must still make: a held ghost adds to its neighbours'
// tracked values, as its owner's hold does on the owner's rank); a ghost's own tracked value
// (zero here, since its rate is not computed) feeds only its own search direction, which its
// owner's replaces before any use. The sums and the maxima cover the rank's own particles; their
// bins are added over the ranks and the maxima taken over them (dfsph_cg_world), and the means
// divide by the world's count, so every rank takes the undivided world's decisions and bits.
#include <cmath>
#include <cstring>
#include <string>

#include "../core/exact_float_sum.h"
#include "../physics/dfsph_cg.h"
#include "cpu_backend_impl.h"

namespace sph {

namespace {
constexpr uint8_t kActive = 1, kBinds = 2;
}  // namespace

DfsphErrors CpuBackend::dfsph_cg_measure(const FluidConstants& fluid, const DfsphWalls& walls, float dt) {
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  const float* density = density_.data();
  const float rho0 = fluid.rest_density;
  float* value = cg_value_.data();
  float* error = dfsph_residual_.data();
  const SimdPasses::DfsphRateFn rate_of = simd_.dfsph_density_rate;
  // A distributed rank's ghosts are skipped (the file's top).
  const uint32_t* halo = origins();
  parallel().for_each(count_, [&](uint32_t i) {
    if (halo && halo[i]) {
      value[i] = 0.0f;
      error[i] = 0.0f;
      return;
    }
    value[i] = dfsph_cg_value(rate_of(fluid, view, columns, walls, i), density[i], rho0, dt);
    error[i] = dfsph_cg_error(value[i], rho0);
  });
  ExactFloatSum sum;
  float largest = 0.0f;
  for (uint32_t i = 0; i < count_; ++i)
    if (!ghost(i)) {
      sum.add(error[i]);
      largest = error[i] > largest ? error[i] : largest;
    }
  dfsph_cg_world(&sum, 1, &largest, 1);
  const int64_t particles = dfsph_cg_particles();
  return {particles > 0 ? static_cast<float>(sum.value() / static_cast<double>(particles)) : 0.0f, largest};
}

int64_t CpuBackend::dfsph_cg_particles() const { return rank_ ? rank_->world_count() : int64_t{count_}; }

void CpuBackend::dfsph_cg_world(ExactFloatSum* sums, int n_sums, float* maxima, int n_maxima) {
  if (!rank_) return;
  constexpr int kTerms = ExactFloatSum::kTerms;
  constexpr int kMostSums = 3;
  if (n_sums > kMostSums) throw Error(Status::Internal, "dfsph_cg_world: more sums than its buffer holds");
  int64_t bins[kMostSums * kTerms];  // (on the stack: no allocation between the agreement and the sum)
  for (int s = 0; s < n_sums; ++s) std::memcpy(bins + s * kTerms, sums[s].terms(), sizeof(int64_t) * kTerms);
  rank_->agree();  // (the exchanges' buffers: a rank that failed there meets the others here)
  rank_->transport().all_sum(bins, n_sums * kTerms);
  if (n_maxima > 0) rank_->transport().all_max(maxima, n_maxima);
  for (int s = 0; s < n_sums; ++s) std::memcpy(sums[s].terms(), bins + s * kTerms, sizeof(int64_t) * kTerms);
}

void CpuBackend::dfsph_cg_hold_contact(const FluidConstants& fluid, const DfsphWalls& walls, float dt,
                                       uint32_t i, Vec3 dv) {
  // D rho / Dt = sum_j m (v_i - v_j) . grad W_ij + v_i . grad rho_b: a change dv of v_i alone
  // adds m dv . grad W_ij to the rate of i and of each neighbour j (grad W_ji = -grad W_ij).
  const KernelCoefficients mk = mass_gradient_kernel(fluid);
  const GridView view = grid_.view();
  const Float4* x = position_.data();
  const Vec3 xi = xyz(x[i]);
  float* value = cg_value_.data();
  float own = walls.records ? dot(boundary_gradient(walls.records[i]), dv) : 0.0f;
  for_each_neighbor_candidate(view, xi, [&](uint32_t j) {
    const Vec3 d = xi - xyz(x[j]);
    const float r2 = length_squared(d);
    if (!(r2 < fluid.kernel.h2) || j == i) return;
    const float term = dot(dv, spiky_gradient(mk, d, std::sqrt(r2)));
    own += term;
    value[j] += dt * term;
  });
  value[i] += dt * own;
}

CpuBackend::SolveOutcome CpuBackend::dfsph_solve_cg(const FluidConstants& fluid, const DfsphWalls& walls,
                                                    float dt, Float4* v, float* carried) {
  const char* refused = walls.records ? "SPH_FEATURE_BOUNDARY_DENSITY" : nullptr;
  // With the walls in the density the operator is symmetric and positive definite
  // (tests/unit/test_dfsph_cg_operator.cpp) and the dam break converges, but a fluid ball started
  // a third inside a tank's floor drives the solve to its cap every substep until the state fails
  // (docs/validation.md, "DFSPH by conjugate gradients"): refused. Refused first when the
  // parameters are set (capi/dfsph_solver_check.h); this holds for the paths that reach the step
  // otherwise.
  if (refused)
    throw Error(Status::Unsupported,
                std::string("step: DFSPH's conjugate gradients solve "
                            "(sph_dfsph_params.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS) "
                            "does not work with ") +
                    refused + " yet; use SPH_DFSPH_JACOBI");
  const Dfsph::Constants& c = fluid.methods.dfsph;
  const DfsphBounds bounds = dfsph_density_bounds(c);
  const uint32_t n = count_;
  float* p = columns_.dfsph_step();  // the search direction, read by the velocity update as k
  float* value = cg_value_.data();
  float* change = cg_change_.data();
  float* z = dfsph_residual_.data();  // the preconditioned residual, or each particle's error
  Float4* dv = cg_velocity_step_.data();
  uint8_t* state = cg_state_.data();
  const float* factor = dfsph_factor_.data();
  const Float4* contact = dfsph_contacts_ ? dfsph_contact_.data() : nullptr;
  const float rho0 = fluid.rest_density;
  const GridView view = grid_.view();
  const NeighborColumns columns = columns_.view();
  const SimdPasses::DfsphVelocityChangeFn change_of = simd_.dfsph_velocity_change;
  const SimdPasses::DfsphRateFn rate_of = simd_.dfsph_density_rate;

  // The warm start, as the Jacobi solve's: half the last substep's pressure, applied once.
  parallel().for_each(n, [&](uint32_t i) {
    p[i] = Dfsph::kWarmStart * carried[i];
    carried[i] = 0.0f;
  });
  dfsph_correct(fluid, walls, dt, v, carried, 1.0f);
  if (rank_) halo_share_velocities(v);  // (the rate pass reads the ghosts' velocities)
  DfsphErrors error = dfsph_cg_measure(fluid, walls, dt);
  const double particles = static_cast<double>(dfsph_cg_particles());

  uint32_t iterations = 0;
  bool restart = true;
  double sz = 0.0;  // value . z over the active set
  while ((dfsph_bounds_unmet(bounds, error) || iterations < Dfsph::kMinIterations) &&
         iterations < c.max_iterations) {
    if (restart) {
      // A new cycle: the set, the binding contacts and the steepest (preconditioned) direction.
      parallel().for_each(n, [&](uint32_t i) {
        const bool active = dfsph_cg_active(value[i], carried[i], factor[i]);
        const bool binds = contact && dfsph_contact_binds(contact[i], xyz(v[i]));
        state[i] = static_cast<uint8_t>((active ? kActive : 0) | (binds ? kBinds : 0));
        p[i] = active ? dfsph_cg_step(value[i], factor[i], dt) : 0.0f;
      });
      ExactFloatSum s;
      for (uint32_t i = 0; i < n; ++i)
        if ((state[i] & kActive) && !ghost(i)) s.add(value[i] * p[i]);
      dfsph_cg_world(&s, 1, nullptr, 0);
      sz = s.value();
      restart = false;
      // Nothing that pressure can reach is off its rest density: done, once the minimum ran (as
      // the Jacobi solve's, whose iterations then apply no pressure either).
      if (sz == 0.0 && iterations >= Dfsph::kMinIterations) break;
    }
    // The operator on p: the velocities p would give, and their rates (on a rank, the velocity
    // update reads the ghosts' p and the rate pass their dv_p: each takes its owner's).
    if (rank_) halo_share_dfsph_step();
    const uint32_t* halo = origins();
    parallel().for_each(n, [&](uint32_t i) {
      if (halo && halo[i]) {
        // A ghost's dv_p is its owner's, shared below; a spring ghost (beyond the density records'
        // halo, which no share reaches and no owned particle's walk reads) keeps 0 rather than the
        // last iteration's data, as the CUDA ranks' cg_rank_direction_kernel.
        dv[i] = make_float4_record(Vec3{0.0f, 0.0f, 0.0f}, 0.0f);
        columns_.set_velocity(i, Vec3{0.0f, 0.0f, 0.0f});
        return;
      }
      Vec3 d = change_of(fluid, view, columns, p, walls, i, dt);
      if (state[i] & kBinds) d = dfsph_contact_project(contact[i], d);
      dv[i] = make_float4_record(d, 0.0f);
      columns_.set_velocity(i, d);
    });
    if (rank_) halo_share_velocities(dv, "DFSPH velocity steps");
    // The rates of dv_p alone (linear, so the tracked values' rounding is never amplified by a
    // long step, as it would be by value(v + dv_p) - value).
    parallel().for_each(n, [&](uint32_t i) {
      // (a ghost's rate would change only its own tracked value, which nothing reads)
      change[i] =
          halo && halo[i] ? 0.0f : dfsph_cg_change(rate_of(fluid, view, columns, walls, i), walls, i, dt);
    });
    ExactFloatSum pq_sum;  // p . A p (the value falls along p)
    for (uint32_t i = 0; i < n; ++i)
      if ((state[i] & kActive) && !ghost(i)) pq_sum.add(-p[i] * change[i]);
    dfsph_cg_world(&pq_sum, 1, nullptr, 0);
    const double pq = pq_sum.value();
    ++iterations;
    if (!(pq > 0.0)) {  // no descent left along p (rounding): a new cycle from the same state
      parallel().for_each(n, [&](uint32_t i) { columns_.set_velocity(i, xyz(v[i])); });
      restart = true;
      continue;
    }
    const float alpha = static_cast<float>(sz / pq);
    parallel().for_each(n, [&](uint32_t i) {
      const Vec3 vi = xyz(v[i]) + xyz(dv[i]) * alpha;
      v[i] = make_float4_record(vi, v[i].w);
      columns_.set_velocity(i, vi);
      carried[i] += alpha * p[i];
      value[i] += alpha * change[i];
    });
    // The contacts, held as the Jacobi solve holds them after each update; a held particle moves
    // only along its wall for the rest of the solve.
    if (contact)
      for (uint32_t i = 0; i < n; ++i) {
        const Vec3 vi = xyz(v[i]);
        if (!dfsph_contact_moved(contact[i], vi)) continue;
        const Vec3 held = respect_contact(contact[i], vi);
        v[i] = make_float4_record(held, v[i].w);
        columns_.set_velocity(i, held);
        state[i] |= kBinds;
        dfsph_cg_hold_contact(fluid, walls, dt, i, held - vi);
      }
    parallel().for_each(n, [&](uint32_t i) { z[i] = dfsph_cg_error(value[i], rho0); });
    // The errors, those outside the set (only what a new set could take: dfsph_cg_restart_due),
    // and value . z over the set for the next direction, taken before the restart rule is known
    // so that one reduction carries the three sums on a rank (a restart drops the third).
    ExactFloatSum sums[3];
    float maxima[2] = {0.0f, 0.0f};  // the largest error, the largest outside the set
    for (uint32_t i = 0; i < n; ++i) {
      if (ghost(i)) continue;
      sums[0].add(z[i]);
      maxima[0] = z[i] > maxima[0] ? z[i] : maxima[0];
      if (!(state[i] & kActive) && factor[i] > 0.0f) {
        sums[1].add(z[i]);
        maxima[1] = z[i] > maxima[1] ? z[i] : maxima[1];
      }
    }
    // z, the Jacobi step of the value over the set.
    parallel().for_each(
        n, [&](uint32_t i) { z[i] = (state[i] & kActive) ? dfsph_cg_step(value[i], factor[i], dt) : 0.0f; });
    for (uint32_t i = 0; i < n; ++i)
      if ((state[i] & kActive) && !ghost(i)) sums[2].add(value[i] * z[i]);
    dfsph_cg_world(sums, 3, maxima, 2);
    error = {static_cast<float>(sums[0].value() / particles), maxima[0]};
    if (dfsph_cg_restart_due(bounds, sums[1].value() / particles, maxima[1])) {
      restart = true;  // the compression outside the set needs a larger set
      continue;
    }
    // The next direction p = z + beta p over the set.
    const double sz_next = sums[2].value();
    const float beta = static_cast<float>(sz_next / sz);
    sz = sz_next;
    parallel().for_each(n, [&](uint32_t i) { p[i] = (state[i] & kActive) ? z[i] + beta * p[i] : 0.0f; });
  }
  // Kept for the warm start, the checkpoints and the pressure attribute: where it pushed
  // (dfsph_cg.h).
  parallel().for_each(n, [&](uint32_t i) { carried[i] = dfsph_cg_kept_pressure(carried[i]); });
  return SolveOutcome{iterations, error.mean, error.largest, dfsph_bounds_unmet(bounds, error), false};
}

}  // namespace sph
