// SPDX-License-Identifier: MIT
// A distributed rank's decomposition and counters, as its checkpoint saves and restores them
// (src/mpi/rank_checkpoint.cpp); the particles' sort keys travel with the particles.
#include "cpu_backend_impl.h"

namespace sph {

DistributedState CpuBackend::distributed_state() const {
  DistributedState s;
  if (!ranks_) return s;
  s.axis = slabs_.axis();
  s.cuts = slabs_.cuts();
  s.cut = slabs_cut_;
  s.counters = halo_counters_;
  s.rebalance_threshold = distributed_options_.rebalance_threshold;
  return s;
}

void CpuBackend::restore_distributed_state(const DistributedState& state) {
  if (!ranks_) throw Error(Status::Internal, "restore_distributed_state: not a distributed world");
  slabs_.restore(state.axis, state.cuts);
  slabs_cut_ = state.cut;
  halo_counters_ = state.counters;
}

}  // namespace sph
