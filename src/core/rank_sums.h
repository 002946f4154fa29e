// SPDX-License-Identifier: MIT
// Sums over the ranks of a distributed world in a fixed order: every rank receives every rank's
// values and adds them in rank order, so each rank holds the same bits, whatever order the MPI
// implementation would reduce in (MPI_Allreduce fixes none). For the colliders' loads
// (docs/distributed.md).
#pragma once

#include <string.h>

#include <string>
#include <vector>

#include "rank_transport.h"
#include "status.h"

namespace sph {

// values[k] becomes the sum over the ranks of their values[k] (rank 0's first, then 1's, ...).
// Collective: every rank calls it with the same n.
template <class T>
void ordered_rank_sum(const RankTransport& ranks, T* values, size_t n) {
  const int size = ranks.size();
  if (size == 1 || n == 0) return;
  const size_t bytes = n * sizeof(T);
  RankBytes mine(bytes);
  memcpy(mine.data(), values, bytes);
  const std::vector<RankBytes> out(static_cast<size_t>(size), mine);
  const std::vector<RankBytes> in = ranks.exchange(out);
  for (int r = 0; r < size; ++r)
    if (in[static_cast<size_t>(r)].size() != bytes)
      throw Error(Status::Internal, "ordered_rank_sum: rank " + std::to_string(r) + " sent " +
                                        std::to_string(in[static_cast<size_t>(r)].size()) +
                                        " bytes, expected " + std::to_string(bytes));
  std::vector<T> term(n);
  memcpy(values, in[0].data(), bytes);
  for (int r = 1; r < size; ++r) {
    memcpy(term.data(), in[static_cast<size_t>(r)].data(), bytes);
    for (size_t k = 0; k < n; ++k) values[k] += term[k];
  }
}

}  // namespace sph
