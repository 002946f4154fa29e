// SPDX-License-Identifier: MIT
// What a distributed world (include/sph_mpi.h) needs from its ranks' transport: collective
// reductions and one all-to-all of bytes. The core and the backends see only this interface;
// src/mpi implements it with MPI (libsph_mpi), so libsph never links MPI. Every call is
// collective: each rank of the world makes the same calls in the same order. exchange and
// gather are agreements too (core/rank_agreement.h): a rank that failed before one, or fails
// in its own buffers, makes every rank throw instead of leaving them in MPI.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <vector>

#include "host_memory.h"

namespace sph {

using RankBytes = HostVector<unsigned char>;

// The calls a transport times (TransportTimes), by the MPI call that carries them: the
// agreements and reductions are Allreduce, an exchange is one Alltoall of its counts and one
// Alltoallv of its bytes, a gather a Gather and a Gatherv, a broadcast two Bcasts. Barrier: the
// waits at the barriers a transport may put before each call (MpiTransport::wait_at_barriers).
enum TransportCall : int {
  kCallAllreduce = 0,
  kCallExscan,
  kCallAlltoall,
  kCallAlltoallv,
  kCallGather,
  kCallGatherv,
  kCallBcast,
  kCallBarrier,
  kTransportCallCount,
};

// Wall time a rank spent inside its transport's calls since the transport was made (issue 19:
// a distributed stage's time is its own work plus the wait there for the slowest rank and the
// transfer, which these tell apart from the packing and sorting around them). Only the MPI calls
// themselves are timed, not the buffers made around them.
struct TransportTimes {
  uint64_t calls[kTransportCallCount] = {};
  double ms[kTransportCallCount] = {};
  double total_ms = 0.0;  // the sum of ms, kept as they are added (a stage reads it twice)
};

class RankTransport {
 public:
  virtual ~RankTransport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Element-wise reductions over the ranks, in place.
  virtual void all_min(int64_t* values, int n) const = 0;
  virtual void all_max(int64_t* values, int n) const = 0;
  virtual void all_sum(int64_t* values, int n) const = 0;
  virtual void all_max(float* values, int n) const = 0;
  // The sum of `value` over the ranks below this one.
  virtual int64_t exclusive_sum(int64_t value) const = 0;
  // send[d] goes to rank d (size() entries); returns what each rank sent to this one.
  virtual std::vector<RankBytes> exchange(const std::vector<RankBytes>& send) const = 0;
  // Every rank's bytes on `root` (in rank order); other ranks get an empty list.
  virtual std::vector<RankBytes> gather(const RankBytes& mine, int root) const = 0;
  // Root's bytes on every rank (no agreement: the agreements' own failure path).
  virtual RankBytes broadcast(const RankBytes& bytes, int root) const = 0;
  // The time inside the calls so far; nullptr where a transport does not time them.
  virtual const TransportTimes* times() const { return nullptr; }
};

}  // namespace sph
