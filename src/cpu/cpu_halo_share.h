// SPDX-License-Identifier: MIT
// The halo's refresh of per-particle values (CpuRankHalo::share, for the records of cpu_halo.cpp,
// cpu_halo_solvers.cpp and cpu_halo_springs.cpp): each owned particle that another rank holds as
// a ghost sends a record to that rank, each ghost takes its owner's.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include "../core/status.h"
#include "cpu_rank_halo.h"

namespace sph {

// Both sides list the particles in the sorted order, which is the same on every rank for the
// particles they share: the receiver reads them in its own order (the ids check it).
template <class Record, class Make, class Apply>
void CpuRankHalo::share(const char* what, Make&& make, Apply&& apply) {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const int size = t.size();
  std::vector<RankBytes> out(static_cast<size_t>(size));
  for (uint32_t i = 0; i < count_; ++i) {
    if (ghost(i)) continue;
    int to[2];
    const int n = slabs_.ghost_destinations(layer(i), me, to);
    if (n == 0) continue;
    const Record r = make(i);
    const unsigned char* from = reinterpret_cast<const unsigned char*>(&r);
    for (int k = 0; k < n; ++k)
      out[static_cast<size_t>(to[k])].insert(out[static_cast<size_t>(to[k])].end(), from, from + sizeof r);
  }
  const std::vector<RankBytes> in = t.exchange(out);
  std::vector<size_t> read(static_cast<size_t>(size), 0);
  for (uint32_t i = 0; i < count_; ++i) {
    if (!ghost(i) || spring_ghost(i)) continue;  // (a spring ghost is no neighbour: no record)
    const size_t from = origin_[i] - 1u;
    Record r;
    if ((read[from] + 1) * sizeof r > in[from].size())
      throw Error(Status::Internal,
                  std::string("halo: rank ") + std::to_string(from) + " sent fewer " + what + " than ghosts");
    std::memcpy(&r, in[from].data() + read[from]++ * sizeof r, sizeof r);
    if (r.id != id_[i])
      throw Error(Status::Internal, std::string("halo: the ") + what + " of rank " + std::to_string(from) +
                                        " came in another order than its ghosts (id " + std::to_string(r.id) +
                                        " for ghost " + std::to_string(id_[i]) + ")");
    apply(i, r);
  }
  for (int r = 0; r < size; ++r)
    if (read[static_cast<size_t>(r)] * sizeof(Record) != in[static_cast<size_t>(r)].size())
      throw Error(Status::Internal,
                  std::string("halo: rank ") + std::to_string(r) + " sent more " + what + " than ghosts");
}

}  // namespace sph
