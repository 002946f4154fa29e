// SPDX-License-Identifier: MIT
// Sources in a distributed world (docs/distributed.md): the sources' state is replicated, so every
// rank decides the same emission. A lattice point is clear where no rank holds a particle within
// the minimum distance (each rank tests its own particles; the ranks agree by a minimum), the
// count that fits is the smallest any rank allows, and each rank keeps the accepted points of its
// own slab with the ids the undivided world would give them (the first free id plus the point's
// place among the accepted ones), so the ids are the world's and never collide.
#include <algorithm>
#include <string>

#include "../physics/grid_hash.h"
#include "rank_agreement.h"
#include "slab_rules.h"
#include "status.h"
#include "world.h"

namespace sph {

void World::agree_clear_points(HostVector<char>& keep) const {
  const RankTransport* ranks = backend_->rank_transport();
  HostVector<int64_t> clear(keep.size());
  for (size_t i = 0; i < keep.size(); ++i) clear[i] = keep[i] ? 1 : 0;
  agree(*ranks);  // (the step's code so far ran on each rank alone: rank_agreement.h)
  if (!clear.empty()) ranks->all_min(clear.data(), static_cast<int>(clear.size()));
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = clear[i] != 0 ? 1 : 0;
}

HostVector<char> World::points_of_this_rank(const HostVector<Vec3>& points) const {
  const DistributedCounters slab = backend_->distributed_counters();
  const float inv = 1.0f / config_.kernel_radius;
  HostVector<char> mine(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const int32_t sub = slab_position(p.x, p.y, p.z, slab.axis, inv);
    mine[i] = sub >= slab.sub_first && sub <= slab.sub_last ? 1 : 0;
  }
  return mine;
}

size_t World::rank_emission_fits(const HostVector<char>& mine, size_t allowed) const {
  // The longest run of accepted points whose share on this rank fits its room.
  const uint32_t free = room();
  int64_t fits = static_cast<int64_t>(allowed);
  uint32_t held = 0;
  for (size_t i = 0; i < allowed; ++i) {
    if (!mine[i]) continue;
    if (held == free) {
      fits = static_cast<int64_t>(i);
      break;
    }
    ++held;
  }
  agree(*backend_->rank_transport(), &fits);  // (an all_min, and an agreement)
  return static_cast<size_t>(fits);
}

void World::emit_on_ranks(const HostVector<Vec3>& points, const HostVector<Vec3>& velocities,
                          const HostVector<char>& mine, uint32_t user_attribute, HostVector<Vec3>& existing) {
  const size_t n = points.size();
  if (static_cast<uint64_t>(next_id_) + n > UINT32_MAX)
    throw Error(Status::Capacity, "source: the world has used up its 2^32 particle ids");
  // Each run of consecutive points of this slab is one append with consecutive ids.
  for (size_t k = 0; k < n;) {
    if (!mine[k]) {
      ++k;
      continue;
    }
    size_t end = k;
    while (end < n && mine[end]) ++end;
    backend_->append(points.data() + k, velocities.data() + k, static_cast<uint32_t>(end - k),
                     next_id_ + static_cast<uint32_t>(k), user_attribute);
    existing.insert(existing.end(), points.begin() + static_cast<std::ptrdiff_t>(k),
                    points.begin() + static_cast<std::ptrdiff_t>(end));
    k = end;
  }
  next_id_ += static_cast<uint32_t>(n);
}

}  // namespace sph
