// SPDX-License-Identifier: MIT
// The C layer of include/sph_mpi.h (libsph_mpi only): a world per rank, its backend attached
// to an MpiTransport; the collective calls agree on their outcome over the ranks.
#include <algorithm>
#include <cstring>
#include <memory>
#include <string>

#include "../capi/guard.h"
#include "../capi/handles.h"
#include "../capi/init_struct.h"
#include "../capi/struct_io.h"
#include "../core/rank_agreement.h"
#include "mpi_transport.h"
#include "mpi_world.h"
#include "sph_mpi.h"

using sph::Error;
using sph::Status;

namespace sph {
namespace {

// A gather's root: a rank of the world's communicator.
void require_root(const RankTransport& ranks, int32_t root) {
  if (root < 0 || root >= ranks.size())
    throw Error(Status::InvalidArgument,
                "root: must be a rank of the world's communicator, got " + std::to_string(root));
}

// COLLECTIVE. A gather's root, the same on every rank: ranks that named different roots would
// each wait in MPI_Gather for messages sent to another root (a hang), so they all refuse instead.
void require_same_root(const RankTransport& ranks, int32_t root) {
  const int64_t mine = root;
  bool same = true;
  compare_over_ranks(ranks, &mine, 1, &same);
  if (!same)
    throw Error(Status::InvalidArgument,
                "root: this rank's " + std::to_string(root) +
                    " differs from another rank's: every rank must pass the same root");
}

constexpr uint32_t kDefaultRebalancePercent = 20;
constexpr uint32_t kMaxRebalancePercent = 10000;

}  // namespace
}  // namespace sph

extern "C" {

SPH_API sph_result SPH_CALL sph_mpi_world_def_init_sized(sph_mpi_world_def* def, uint32_t size) {
  return sph::init_user_struct("sph_mpi_world_def_init", "def", def, size);
}

SPH_API sph_result SPH_CALL sph_mpi_counts_init_sized(sph_mpi_counts* counts, uint32_t size) {
  return sph::init_user_struct("sph_mpi_counts_init", "counts", counts, size);
}

SPH_API sph_result SPH_CALL sph_mpi_world_create(sph_context* context, const sph_world_def* def, int32_t comm,
                                                 const sph_mpi_world_def* mpi_def, sph_world** out) {
  return sph::guarded("sph_mpi_world_create", context, [&] {
    // The communicator first: every rank duplicates it (collective), and from here on the ranks
    // meet, so that a rank whose own arguments or world fail does not leave the others waiting in
    // the next collective call: each rank's checks and world are agreed (a failure on one rank is
    // every rank's, the others' messages naming it; core/rank_agreement.h).
    auto transport = std::make_shared<sph::MpiTransport>(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)));
    const sph::MpiTransport& ranks = *transport;
    std::unique_ptr<sph::ContextHold> hold;
    sph_world_def d;
    sph::DistributedOptions options;
    int64_t percent_given = 0;
    sph::agreed(ranks, [&] {
      hold = std::make_unique<sph::ContextHold>(context);
      if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
      sph_mpi_world_def m;
      if (mpi_def) {
        m = sph::read_user_struct(mpi_def, "mpi_def");
      } else {
        m = sph::zeroed_struct<sph_mpi_world_def>();
      }
      const uint32_t percent =
          m.rebalance_threshold_percent == 0 ? sph::kDefaultRebalancePercent : m.rebalance_threshold_percent;
      if (percent > sph::kMaxRebalancePercent)
        throw Error(Status::InvalidArgument,
                    "mpi_def->rebalance_threshold_percent: must be in [1, 10000] (0: the default, 20), got " +
                        std::to_string(percent));
      options.rebalance_threshold = percent / 100.0;
      percent_given = percent;
      d = sph::read_user_struct(def, "def");
    });
    // The ranks rebalance together (a rank that skipped a rebalance the others began left them
    // in mismatched reductions: one rank's step failed, the others' waited), so the threshold is
    // one value on every rank.
    bool same_threshold = true;
    sph::compare_over_ranks(ranks, &percent_given, 1, &same_threshold);
    if (!same_threshold)
      throw Error(
          Status::InvalidArgument,
          "mpi_def->rebalance_threshold_percent: this rank's " + std::to_string(percent_given) +
              " differs from another rank's: every rank must pass the same (the ranks rebalance together)");
    // One backend on every rank (before any world is made: a CUDA world's allocations are not
    // wasted on a refusal, and the refusal is this one, not a rank's own): a CPU rank and a CUDA
    // rank keep their particles, their tables and what they send each other in different layouts
    // (docs/distributed.md).
    const int64_t cuda = hold->get()->backend == sph::BackendKind::Cuda ? 1 : 0;
    bool same = true;
    sph::compare_over_ranks(ranks, &cuda, 1, &same);
    if (!same)
      throw Error(Status::InvalidArgument, std::string("context: this rank's backend is ") +
                                               (cuda ? "CUDA" : "the CPU") + " and another rank's is " +
                                               (cuda ? "the CPU" : "CUDA") +
                                               ": a distributed world needs one backend on every rank");
    std::unique_ptr<sph_world> world;
    sph::agreed(ranks, [&] {
      world = sph::make_world(context, d);
      world->world->backend().attach_ranks(transport, options);
    });
    // One world tag on every rank, rank 0's, so that the replicated scene objects have the same
    // ids on every rank (a rank's context may have made other worlds before this one).
    int64_t tag = ranks.rank() == 0 ? world->world->id_tag() : 0;
    ranks.all_sum(&tag, 1);
    world->world->set_id_tag(static_cast<uint16_t>(tag));
    *out = sph::publish_on_every_rank(ranks, std::move(world));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_add_particles(sph_world* world, const float* positions,
                                                        const float* velocities, uint32_t count,
                                                        uint32_t* out_first_id) {
  return sph::guarded("sph_mpi_world_add_particles", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    sph::World& w = *world->world;
    const sph::RankTransport& ranks = sph::ranks_of(world);
    sph::agreed(ranks, [&] { sph::WorldLock::require_device_not_lost(world); });
    // The ids: rank order, after what the world has numbered.
    const int64_t below = ranks.exclusive_sum(count);
    int64_t total = count;
    ranks.all_sum(&total, 1);
    const uint32_t next_id_before = w.next_id();
    const uint32_t count_before = w.particle_count();
    bool refused = false;
    Status status = Status::Ok;
    std::string message;
    try {
      if (static_cast<uint64_t>(next_id_before) + static_cast<uint64_t>(total) > UINT32_MAX)
        throw Error(Status::Capacity, "count: the world's ranks add " + std::to_string(total) +
                                          " particles, past its 2^32 particle ids");
      if (count > 0 && !positions) throw Error(Status::InvalidArgument, "positions: is NULL");
      sph::HostVector<sph::Vec3> p(count), v(velocities ? count : 0u);
      for (uint32_t i = 0; i < count; ++i) {
        p[i] = sph::Vec3{positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
        if (velocities) v[i] = sph::Vec3{velocities[3 * i], velocities[3 * i + 1], velocities[3 * i + 2]};
      }
      w.add_rank_particles(p, velocities ? &v : nullptr, next_id_before + static_cast<uint32_t>(below),
                           next_id_before + static_cast<uint32_t>(total));
    } catch (...) {
      // (An allocation too: the other ranks wait in the reduction below for this one.)
      const Error e = sph::current_error();
      refused = true;
      status = e.status();
      message = e.what();
    }
    // The lowest refusing rank (its rank + 1; 0: none), so the others' messages can name it.
    int64_t refusing = refused ? -(static_cast<int64_t>(ranks.rank()) + 1) : 0;
    ranks.all_min(&refusing, 1);
    if (refused) throw Error(status, message);
    if (refusing != 0) {
      w.undo_rank_particles(count_before, next_id_before);
      throw Error(Status::InvalidArgument,
                  "rank " + std::to_string(-refusing - 1) +
                      "'s particles were refused (its error says why); no rank added any");
    }
    if (out_first_id) *out_first_id = next_id_before + static_cast<uint32_t>(below);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_step(sph_world* world, float frame_dt) {
  return sph_world_step(world, frame_dt);
}

SPH_API sph_result SPH_CALL sph_mpi_world_get_counts(const sph_world* world, sph_mpi_counts* out) {
  return sph::guarded("sph_mpi_world_get_counts", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    const sph::RankTransport& ranks = sph::ranks_of(world);
    sph::agreed(ranks, [&] { sph::WorldLock::require_device_not_lost(world); });
    const sph::DistributedCounters c = world->world->backend().distributed_counters();
    int64_t sums[3] = {world->world->particle_count(), c.ghosts, c.migrated_out};
    ranks.all_sum(sums, 3);  // (before any check of this rank's arguments: the other ranks wait for it)
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    sph_mpi_counts r = sph::zeroed_struct<sph_mpi_counts>();
    r.rank = ranks.rank();
    r.rank_count = ranks.size();
    r.local_count = world->world->particle_count();
    r.global_count = static_cast<uint64_t>(sums[0]);
    r.global_ghosts = static_cast<uint64_t>(sums[1]);
    r.migrated = static_cast<uint64_t>(sums[2]);
    r.local_ghosts = c.ghosts;
    r.rebalances = c.rebalances;
    r.axis = c.axis;
    r.slab_first = c.slab_first;
    r.slab_last = c.slab_last;
    r.slab_sub_first = c.sub_first;
    r.slab_sub_last = c.sub_last;
    sph::write_output_struct(out, r, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_gather(const sph_world* world, int32_t root, float* positions,
                                                 float* velocities, uint32_t* ids, uint64_t capacity,
                                                 uint64_t* out_count) {
  return sph::guarded("sph_mpi_world_gather", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    const sph::RankTransport& ranks = sph::ranks_of(world);
    struct Record {
      uint32_t id;
      float x[3], v[3];
    };
    const sph::Backend& b = world->world->backend();
    const uint32_t n = world->world->particle_count();
    sph::HostVector<Record> mine;
    // This rank's records, agreed: a rank whose device copy or allocation fails (or whose device
    // was lost before the call) must not leave the others waiting in the gather.
    sph::agreed(ranks, [&] {
      sph::WorldLock::require_device_not_lost(world);
      sph::require_root(ranks, root);
      mine.resize(n);
      if (n > 0) {
        b.copy_attribute(sph::AttributeKind::Id, 0, n, &mine[0].id, sizeof(Record));
        b.copy_attribute(sph::AttributeKind::Position, 0, n, mine[0].x, sizeof(Record));
        b.copy_attribute(sph::AttributeKind::Velocity, 0, n, mine[0].v, sizeof(Record));
      }
    });
    sph::require_same_root(ranks, root);
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(mine.data());
    const std::vector<sph::RankBytes> all =
        ranks.gather(sph::RankBytes(bytes, bytes + n * sizeof(Record)), root);
    if (out_count) *out_count = 0;
    if (ranks.rank() != root) return SPH_OK;
    sph::HostVector<Record> records;
    for (const sph::RankBytes& r : all) {
      const size_t k = r.size() / sizeof(Record);
      const size_t at = records.size();
      records.resize(at + k);
      if (k > 0) std::memcpy(&records[at], r.data(), k * sizeof(Record));
    }
    std::sort(records.begin(), records.end(), [](const Record& a, const Record& c) { return a.id < c.id; });
    if (out_count) *out_count = records.size();
    if (capacity < records.size())
      throw Error(Status::InvalidArgument, "capacity: " + std::to_string(capacity) +
                                               " is below the world's " + std::to_string(records.size()) +
                                               " particles");
    for (size_t i = 0; i < records.size(); ++i) {
      if (positions) std::memcpy(positions + 3 * i, records[i].x, sizeof records[i].x);
      if (velocities) std::memcpy(velocities + 3 * i, records[i].v, sizeof records[i].v);
      if (ids) ids[i] = records[i].id;
    }
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_gather_removed_ids(const sph_world* world, int32_t root,
                                                             uint32_t* ids, uint32_t capacity,
                                                             uint32_t* out_count) {
  return sph::guarded("sph_mpi_world_gather_removed_ids", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    const sph::RankTransport& ranks = sph::ranks_of(world);
    sph::RankBytes packed;
    sph::agreed(ranks, [&] {
      sph::WorldLock::require_device_not_lost(world);
      sph::require_root(ranks, root);
      if (ranks.rank() == root && !out_count) throw Error(Status::InvalidArgument, "out_count: is NULL");
      if (ranks.rank() == root && capacity > 0 && !ids)
        throw Error(Status::InvalidArgument, "ids: is NULL but capacity > 0");
      const sph::HostVector<uint32_t>& mine = world->world->removed_ids();
      const unsigned char* bytes = reinterpret_cast<const unsigned char*>(mine.data());
      packed.assign(bytes, bytes + mine.size() * sizeof(uint32_t));
    });
    sph::require_same_root(ranks, root);
    const std::vector<sph::RankBytes> all = ranks.gather(packed, root);
    // Whether root's array was too small, on every rank: "call again, collectively" needs every
    // rank to know (before, the others returned SPH_OK, and a caller that retried on
    // SPH_INCOMPLETE retried on root alone, whose next collective then met the others' next call).
    size_t world_removed = 0;
    for (const sph::RankBytes& r : all) world_removed += r.size() / sizeof(uint32_t);
    int64_t incomplete = ranks.rank() == root && world_removed > capacity ? 1 : 0;
    ranks.all_max(&incomplete, 1);
    if (ranks.rank() != root) {
      if (out_count) *out_count = 0;
      return incomplete ? SPH_INCOMPLETE : SPH_OK;
    }
    sph::HostVector<uint32_t> removed;
    for (const sph::RankBytes& r : all) {
      const size_t at = removed.size();
      removed.resize(at + r.size() / sizeof(uint32_t));
      if (r.size() > 0) std::memcpy(removed.data() + at, r.data(), r.size());
    }
    std::sort(removed.begin(), removed.end());
    const size_t written = std::min<size_t>(removed.size(), capacity);
    if (written > 0) std::memcpy(ids, removed.data(), written * sizeof(uint32_t));
    *out_count = static_cast<uint32_t>(removed.size());
    return written < removed.size() ? SPH_INCOMPLETE : SPH_OK;
  });
}

}  // extern "C"
