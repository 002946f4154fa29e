// SPDX-License-Identifier: MIT
// A distributed rank's decomposition and counters, as its checkpoint saves and restores them
// (src/mpi/api_mpi_checkpoint.cpp); the particles' sort keys travel with the particles.
#include "cpu_backend_impl.h"
#include "cpu_rank_halo.h"

namespace sph {

DistributedState CpuRankHalo::state() const {
  DistributedState s;
  s.axis = slabs_.axis();
  s.cuts = slabs_.cuts();
  s.cut = slabs_cut_;
  s.counters = counters_;
  s.rebalance_threshold = options_.rebalance_threshold;
  return s;
}

void CpuRankHalo::restore(const DistributedState& state) {
  slabs_.restore(state.axis, state.cuts);
  slabs_cut_ = state.cut;
  counters_ = state.counters;
}

DistributedState CpuBackend::distributed_state() const { return rank_ ? rank_->state() : DistributedState{}; }

void CpuBackend::restore_distributed_state(const DistributedState& state) {
  if (!rank_) throw Error(Status::Internal, "restore_distributed_state: not a distributed world");
  rank_->restore(state);
}

}  // namespace sph
