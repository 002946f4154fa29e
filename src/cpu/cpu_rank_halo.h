// SPDX-License-Identifier: MIT
// The CPU backend as one rank of a distributed world (include/sph_mpi.h, docs/distributed.md):
// what a rank holds beyond an undivided world's backend, and the halo's steps that move
// particles between the ranks. The backend owns one only when distributed (attach_ranks), and
// decides which of its values the ghosts take and when (cpu_halo.cpp's halo_share_*); this
// class knows which particles are ghosts, where each particle goes, and how a record crosses to
// the ranks beside. Between substeps a rank holds the particles it owns; during one it also
// holds ghosts (origins() != 0), the particles it does not own in the cell layers its slab meets
// and those beside them (core/slab_rules.h). The sort
// takes the particles in the order of their keys (sort_keys(): slot and place in it at the last
// sort, the same on every rank), so each cell lists its particles in the order one undivided
// world would, and every sum runs in the same order. Each step is collective, and each place
// where the ranks meet after code that can fail is an agreement (core/rank_agreement.h).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <vector>

#include "../core/distributed.h"
#include "../core/host_memory.h"
#include "../core/particle_arrays.h"
#include "../core/rank_transport.h"
#include "../core/slab_decomposition.h"
#include "../physics/float4_types.h"
#include "../physics/grid_hash.h"
#include "../physics/springs.h"
#include "cpu_id_table.h"
#include "cpu_parallel.h"
#include "cpu_particle_store.h"

namespace sph {

class CpuNeighborGrid;
struct ColliderLoadSums;
struct ProbeGather;
struct ProbeView;

// The backend's particles as its rank moves them: the store and its count (which the migration,
// the ghosts and their removal change), the list of the particles a permutation keeps (shared
// with the sinks, which never run inside a halo step), the workers of its loops, and the arrays
// the halo's own steps read (the springs' null without SPH_FEATURE_SPRINGS).
struct CpuRankParticles {
  CpuParticleStore& store;
  uint32_t& count;
  HostVector<uint32_t>& keep;
  const CpuParallel& workers;
  float kernel_radius;
  CpuArrayRef<Float4> position;
  CpuArrayRef<uint32_t> id;
  CpuArrayRef<SpringList> springs;
  CpuArrayRef<uint32_t> spring_candidates;
  CpuArrayRef<uint32_t> link_from;
};

class CpuRankHalo {
 public:
  // Registers the rank's own arrays (the sort keys, carried; the origins, sorted) in the store.
  CpuRankHalo(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options,
              const CpuRankParticles& particles);

  const RankTransport& transport() const { return *ranks_; }
  // The hash+sort stage's parts (gather's own; the backend adds the grid's, the reorder's and the
  // keys').
  const HaloPhaseTimes& phase_times() const { return phase_times_; }
  HaloPhaseTimes& phase_times() { return phase_times_; }
  const std::shared_ptr<const RankTransport>& shared_transport() const { return ranks_; }
  DistributedCounters counters() const;
  // The decomposition and counters a rank's checkpoint carries (cpu_rank_state.cpp).
  DistributedState state() const;
  void restore(const DistributedState& state);

  // A ghost of this substep.
  bool ghost(uint32_t i) const { return origin_[i] != 0u; }
  // Per particle: 0 owned, else 1 + the rank the ghost came from (+ the rank count for a spring
  // ghost).
  const uint32_t* origins() const { return origin_.data(); }
  uint64_t* sort_keys() const { return sort_key_.data(); }
  // The particles every rank owns, this substep.
  int64_t world_count() const { return world_count_; }

  // Whether `flag` is raised on any rank; an agreement, as every collective step below is: it
  // throws on every rank when one failed since the last.
  bool any(bool flag) const;
  // An agreement of its own, before ranks meet after code that can fail.
  void agree() const;
  // The frame's start, after an agreement: new slabs when the ranks are out of balance (held:
  // the rank count's entries, allocated before that agreement; core/slab_rebalance.h).
  void rebalance(std::vector<int64_t>& held);
  // Before the sort: owned particles that left the slab migrate, ghosts arrive; the world's grid
  // shape and this rank's sort order for the sort.
  void gather();
  const GridShape* grid_shape() const { return &shape_; }
  const uint32_t* visit_order() const { return visit_.data(); }
  // After the sort: the keys of the new order (and the spring lists' partners follow it).
  void after_sort(const CpuNeighborGrid& grid);
  // Each owned particle beside another rank's slab sends make(i) (a Record, which starts with
  // the particle's id) to that rank; each ghost takes apply(i, record) from its owner's
  // (cpu_halo_share.h). `what` names the records in an error.
  template <class Record, class Make, class Apply>
  void share(const char* what, Make&& make, Apply&& apply);
  // Springs' linking, between its passes: each ghost takes its owner's candidates.
  void share_spring_candidates();
  // The substep's end: the spring lists back to ids, the ghosts dropped.
  void drop_ghosts();
  // Each probe point's sums from the rank whose slab holds it; the colliders' load sums of the
  // frame added over the ranks in rank order (cpu_halo_solvers.cpp).
  void pick_probe_points(const ProbeView* probes, size_t probe_count, ProbeGather* points,
                         size_t point_count) const;
  // Whether this rank's slab holds sample point x (its gather of x is the one every rank takes).
  bool owns_probe_point(Vec3 x) const;
  void sum_loads(ColliderLoadSums* sums, size_t count) const;

 private:
  CpuParallel parallel() const { return workers_.for_items(count_); }
  // A spring ghost: a ghost that is only the far end of an owned particle's spring, from past the
  // halo (cpu_halo_springs.cpp). No neighbour pass reads it.
  bool spring_ghost(uint32_t i) const { return origin_[i] > static_cast<uint32_t>(ranks_->size()); }
  // Particle i's cell layer along the slabs' axis, and its sub-layer (slab_rules.h).
  int32_t layer(uint32_t i) const;
  int32_t sub_layer(uint32_t i) const;
  // Whether an array moves with its particle: the carried ones, and RK4's stage state.
  static bool travels(const ParticleArraySpec& spec);
  // The travelling arrays of the particles `which` lists into `out` (replacing what it held), array
  // after array, each array's rows in `which`'s order (the CUDA rank's layout, DeviceHalo::pack) /
  // appends the particles `in` holds (one pack's bytes) with origin `origin`; returns how many.
  void pack(const HostVector<uint32_t>& which, RankBytes& out) const;
  uint32_t unpack(const RankBytes& in, uint32_t origin);
  // One particle's bytes of the travelling arrays.
  size_t travelling_bytes() const;
  // visit_: the held particles by sort key, then id (the sort's order; cpu_halo_visit.cpp).
  void order_visits();
  // Keeps the particles keep_ lists (ascending), in that order.
  void keep(size_t kept);
  // Springs across ranks (cpu_halo_springs.cpp). Outside a substep's sorted part the spring
  // lists name their partners by id. gather_spring_partners (after the ghosts' arrival): the
  // owned lists' ids become storage indices; each partner neither owned nor a ghost comes from
  // its owner as a spring ghost (none: a sink removed it, and the spring is dropped, as a sink's
  // removal drops it in the undivided world). resolve_springs (after the sort): the partners
  // follow the sort (order: the sort's, new index i holds old index order[i]). springs_to_ids
  // (the substep's end, before the ghosts go): back to ids. index_ids: id_table_ from the
  // particles held now.
  void gather_spring_partners(uint32_t owned);
  void resolve_springs(const uint32_t* order);
  void springs_to_ids();
  void index_ids();

  std::shared_ptr<const RankTransport> ranks_;
  DistributedOptions options_;
  // The backend's (CpuRankParticles).
  CpuParticleStore& store_;
  uint32_t& count_;
  HostVector<uint32_t>& keep_;
  const CpuParallel& workers_;
  float kernel_radius_;
  CpuArrayRef<Float4> position_;
  CpuArrayRef<uint32_t> id_;
  CpuArrayRef<SpringList> springs_;
  CpuArrayRef<uint32_t> spring_candidates_;
  CpuArrayRef<uint32_t> link_from_;
  // The rank's own.
  SlabDecomposition slabs_;
  bool slabs_cut_ = false;
  DistributedCounters counters_;
  GridShape shape_{};        // the rank's table (rank_grid_shape)
  GridShape world_shape_{};  // the undivided world's, whose slots name the sort keys
  bool own_table_ = false;   // shape_ is the rank's band of world_shape_, not world_shape_ itself
  HaloPhaseTimes phase_times_;
  HostVector<uint32_t> visit_;
  // gather's ordered runs of particles (where each starts), merged into visit_ when they are at
  // most kMergedRuns; more are sorted.
  static constexpr size_t kMergedRuns = 64;
  HostVector<uint32_t> run_starts_;
  HostVector<uint32_t> merged_;              // the merge's other buffer
  std::vector<HostVector<uint32_t>> sends_;  // the particles gather sends each rank (pack's `which`)
  int64_t world_count_ = 0;
  CpuArrayRef<uint64_t> sort_key_;  // Carried
  CpuArrayRef<uint32_t> origin_;    // Sorted (origins())
  // Springs: the held particles' ids to their indices, the partners waiting for spring ghosts
  // (kSpringSlots ids per owned particle), the sort's inverse permutation; whether the owned
  // lists hold storage indices (from the gather to the substep's end) or ids.
  CpuIdTable id_table_;
  HostVector<uint32_t> missing_;
  HostVector<uint32_t> inverse_;
  bool springs_indexed_ = false;
};

}  // namespace sph
