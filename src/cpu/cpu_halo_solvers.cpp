// SPDX-License-Identifier: MIT
// A distributed rank's exchanges for what reads more than the density pass (docs/distributed.md):
//   DFSPH      after its density pass the ghosts take their owners' density, factor and neighbour
//              count; inside each solve iteration, their velocities after each velocity update
//              and their pressure steps k after each rate pass (the next pass reads both of its
//              neighbours; core/dfsph_jacobi_loop.h, the loop the CUDA rank runs too); the
//              solve's mean error is an exact sum whose bins are added over the ranks
//              (cpu_dfsph_solver.cpp): every rank runs the undivided world's iterations; the
//              density solve by conjugate gradients (cpu_dfsph_cg.cpp) shares the velocities
//              after its warm start, then in each iteration the search directions p (in the
//              steps' column) and the velocity steps dv_p, and adds its sums' bins likewise;
//   probes     each sample point is gathered by the rank whose slab holds its sub-layer (its
//              neighbour cells are complete there, in the undivided world's order) and every
//              rank takes that rank's sums (core/rank_probe_points.h, the CUDA rank's too):
//              each rank reads the world's bits;
//   loads      each rank sums the impulses of its own particles; the frame's sums are added
//              over the ranks in rank order, so every rank reads the same world's value.
#include <string>

#include "../core/halo_records.h"
#include "../core/rank_probe_points.h"
#include "../core/rank_sums.h"
#include "cpu_backend_impl.h"
#include "cpu_halo_share.h"

namespace sph {

void CpuBackend::halo_share_dfsph_density() {
  using Record = HaloDfsphDensityRecord;
  float* factor = dfsph_factor_.data();
  rank_->share<Record>(
      "DFSPH densities",
      [&](uint32_t i) {
        return Record{id_[i], density_[i], factor[i], velocity_[i].w, neighbors_[i]};
      },
      [&](uint32_t i, const Record& r) {
        density_[i] = r.density;
        factor[i] = r.factor;
        velocity_[i].w = r.inv_density;
        neighbors_[i] = r.neighbors;
        columns_.set_density(i, position_[i].w, r.inv_density);
        columns_.set_neighbor_count(i, r.neighbors);
      });
}

void CpuBackend::halo_share_velocities(Float4* v, const char* what) {
  using Record = HaloVelocityRecord;  // (its padding a member, zeroed)
  rank_->share<Record>(
      what,
      [&](uint32_t i) {
        return Record{id_[i], {0u, 0u, 0u}, v[i]};
      },
      [&](uint32_t i, const Record& r) {
        v[i] = r.velocity;
        columns_.set_velocity(i, xyz(r.velocity));
      });
}

void CpuBackend::halo_share_dfsph_step() {
  using Record = HaloDfsphStepRecord;
  float* k = columns_.dfsph_step();
  rank_->share<Record>(
      "DFSPH pressure steps",
      [&](uint32_t i) {
        return Record{id_[i], k[i]};
      },
      [&](uint32_t i, const Record& r) { k[i] = r.k; });
}

void CpuRankHalo::pick_probe_points(const ProbeView* probes, size_t probe_count, ProbeGather* points,
                                    size_t point_count) const {
  pick_rank_probe_points(*ranks_, slabs_, kernel_radius_, probes, probe_count, points, point_count);
}

bool CpuRankHalo::owns_probe_point(Vec3 x) const {
  return probe_point_owner(slabs_, kernel_radius_, x) == ranks_->rank();
}

void CpuRankHalo::sum_loads(ColliderLoadSums* loads, size_t count) const {
  HostVector<double> sums;
  sums.reserve(6 * count);
  for (size_t c = 0; c < count; ++c) {
    sums.insert(sums.end(), loads[c].linear, loads[c].linear + 3);
    sums.insert(sums.end(), loads[c].angular, loads[c].angular + 3);
  }
  ordered_rank_sum(*ranks_, sums.data(), sums.size());
  for (size_t c = 0; c < count; ++c)
    for (int k = 0; k < 3; ++k) {
      loads[c].linear[k] = sums[6 * c + static_cast<size_t>(k)];
      loads[c].angular[k] = sums[6 * c + 3 + static_cast<size_t>(k)];
    }
}

}  // namespace sph
