// SPDX-License-Identifier: MIT
// RankTransport (core/rank_transport.h) over MPI: the one file set of the library that sees
// mpi.h, built into libsph_mpi only.
#pragma once

#include <mpi.h>

#include "../core/rank_transport.h"

namespace sph {

// The collectives this transport issues, named for the collective check (below).
enum class Collective : int64_t {
  AllMinInt64 = 1,
  AllMaxInt64,
  AllSumInt64,
  AllMaxFloat,
  ExclusiveSum,
  Alltoall,
  Alltoallv,
  Gather,
  Gatherv,
  BroadcastSize,
  BroadcastBytes,
};

class MpiTransport final : public RankTransport {
 public:
  // Duplicates `comm`, so the world's messages never meet the caller's. Throws Error.
  // COLLECTIVE: the ranks agree on the collective check (SPH_MPI_CHECK_COLLECTIVES=1 on every
  // rank turns it on; docs/distributed.md): before each collective, one all-reduce of the call's
  // signature, so that ranks in different collectives (a bug in the library's rank code) all
  // throw Internal naming the calls instead of hanging or truncating in MPI.
  explicit MpiTransport(MPI_Comm comm);
  ~MpiTransport() override;
  MpiTransport(const MpiTransport&) = delete;
  MpiTransport& operator=(const MpiTransport&) = delete;

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void all_min(int64_t* values, int n) const override;
  void all_max(int64_t* values, int n) const override;
  void all_sum(int64_t* values, int n) const override;
  void all_max(float* values, int n) const override;
  int64_t exclusive_sum(int64_t value) const override;
  std::vector<RankBytes> exchange(const std::vector<RankBytes>& send) const override;
  std::vector<RankBytes> gather(const RankBytes& mine, int root) const override;
  RankBytes broadcast(const RankBytes& bytes, int root) const override;

  const TransportTimes* times() const override { return &times_; }

  bool checks_collectives() const { return check_collectives_; }

  // COLLECTIVE in effect: every rank must turn it on (or off) before its next call, or the
  // ranks meet a barrier against another call. On, each timed call waits at an MPI_Barrier first
  // (timed as kCallBarrier): the barrier holds the wait for the slowest rank, and what the call
  // itself takes after it is the transfer. Off by default (the extra barrier costs a latency a
  // call); bench/mpi_halo's --wait-barriers turns it on. Const as the timing is: instrumentation,
  // not the transport's state. But it changes which collectives a rank calls: every rank must set
  // the same (a rank with the barriers and one without would meet in MPI_Barrier against another
  // call); the collective check (SPH_MPI_CHECK_COLLECTIVES=1) compares it with each call's kind.
  void wait_at_barriers(bool on) const { wait_at_barriers_ = on; }

 private:
  // With the check on: every rank's (kind, detail) must be the same, else every rank throws
  // Internal (an AgreedRankFailure: no rank joins the others again on its way out). `detail` is
  // the element count, or the root of a rooted call; 0 for the v-variants, whose counts differ
  // between ranks by design.
  void match(Collective kind, int64_t detail) const;
  // Runs one MPI call (a callable returning its code) and adds its wall time to times_[call];
  // first a timed barrier where wait_at_barriers is on, unless `barrier` is false.
  template <class Call>
  int timed(TransportCall call, Call&& mpi, bool barrier = true) const;

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  bool check_collectives_ = false;
  mutable bool wait_at_barriers_ = false;
  mutable TransportTimes times_;
};

}  // namespace sph
