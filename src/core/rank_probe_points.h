// SPDX-License-Identifier: MIT
// Probes and gauges in a distributed world (docs/distributed.md), for both backends' ranks (the
// CPU rank's points are on the host; the CUDA rank downloads its points, calls this, and uploads
// them): every rank gathers every sample point over its own particles and ghosts, but only the
// rank whose slab holds the point's sub-layer has all of the point's neighbour cells, listed in
// the undivided world's order, so every rank takes that rank's gather of the point (one
// all-to-all of the points per sampled substep). Each rank then adds the same points in the same
// order: the readings are the undivided world's, bit for bit, on every rank.
#pragma once

#include <stddef.h>

#include <cstring>
#include <string>
#include <vector>

#include "../physics/grid_hash.h"
#include "../physics/probe_sampling.h"
#include "rank_transport.h"
#include "slab_decomposition.h"
#include "slab_rules.h"
#include "status.h"

namespace sph {

// The rank whose slab holds sample point x's sub-layer: the one whose gather of it counts.
inline int probe_point_owner(const SlabDecomposition& slabs, float kernel_radius, Vec3 x) {
  return slabs.owner(slab_position(x.x, x.y, x.z, slabs.axis(), 1.0f / kernel_radius));
}

// points[0, point_count): this rank's gathers of the sample points of probes[0, probe_count), in
// the order of their first points (those of points another rank owns may be left unsampled: they
// are replaced); replaced by each point's owner's.
inline void pick_rank_probe_points(const RankTransport& t, const SlabDecomposition& slabs,
                                   float kernel_radius, const ProbeView* probes, size_t probe_count,
                                   ProbeGather* points, size_t point_count) {
  static_assert(sizeof(ProbeGather) == 6 * sizeof(float), "a probe gather is six floats");
  if (t.size() == 1 || point_count == 0) return;
  const size_t bytes = point_count * sizeof(ProbeGather);
  RankBytes mine(bytes);
  std::memcpy(mine.data(), points, bytes);
  const std::vector<RankBytes> in = t.exchange(std::vector<RankBytes>(static_cast<size_t>(t.size()), mine));
  for (size_t r = 0; r < in.size(); ++r)
    if (in[r].size() != bytes)
      throw Error(Status::Internal,
                  "halo: rank " + std::to_string(r) + " sampled another number of probe points");
  for (size_t k = 0; k < probe_count; ++k) {
    const ProbeView& p = probes[k];
    for (uint32_t q = 0; q < p.point_count; ++q) {
      const int owner = probe_point_owner(slabs, kernel_radius, probe_point(p, q));
      const size_t at = p.first_point + q;
      std::memcpy(&points[at], in[static_cast<size_t>(owner)].data() + at * sizeof(ProbeGather),
                  sizeof(ProbeGather));
    }
  }
}

}  // namespace sph
