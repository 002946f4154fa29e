// SPDX-License-Identifier: MIT
// The CPU backend as one rank of a distributed world (include/sph_mpi.h, docs/distributed.md):
// host-staged halos over a RankTransport (MPI in libsph_mpi). A substep of a rank runs the
// single world's passes over its own particles plus ghosts, with four steps of its own:
//   before the sort   particles that left the slab migrate to their owner (every carried
//                     array), the ghosts arrive (the particles it does not own in the layers
//                     its slab meets and those beside them), the world's grid shape is reduced
//                     from every rank's extent;
//   after the sort    each particle's key becomes its slot and place in the slot (springs: the
//                     lists' partners, ids until the ghosts came, follow the sort;
//                     cpu_halo_springs.cpp);
//   after density     the ghosts take their owners' density, pressure and neighbour count
//                     (the force pass reads them), again after the normalised density's filter
//                     and the diffusion, and their colour normals after that pass;
//   the substep's end ghosts are dropped, the max speed and acceleration (the next step size)
//                     and the first non-finite particle are reduced over the ranks (RK4: at
//                     each stage's end, as each stage sorts and gathers anew).
// DFSPH's per-iteration exchanges, the probes' and the loads' sums: cpu_halo_solvers.cpp.
// The particles' moves, the keys and the records' wire are CpuRankHalo's (cpu_rank_halo.h; its
// steps first below; the messages' layout, pack and unpack: cpu_halo_pack.cpp); the backend's side, last
// below, picks the values the ghosts take and reduces the step's inputs, which are the backend's. Each place
// where the ranks meet after code that can fail (an allocation, a crowded cell) is an agreement
// (core/rank_agreement.h): a rank that failed joins the others' next one from its catch block
// (rethrow_step_failure), and every rank returns the error instead of waiting. The sort takes particles in
// key order, so each cell's particles come in the order the undivided world's stable sort gives them: the
// neighbour sums add in the same order and a distributed world steps the single world's bits (while the
// grid's table covers the particles' extent without folding; docs/distributed.md).
#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../core/grid_layout.h"
#include "../core/halo_records.h"
#include "../core/rank_agreement.h"
#include "../core/slab_rebalance.h"
#include "../core/slab_rules.h"
#include "cpu_backend_impl.h"
#include "cpu_halo_share.h"
#include "cpu_neighbor_grid.h"
#include "cpu_rank_halo.h"

namespace sph {

namespace {

constexpr const char* kArrayOrigin = "distributed_origin";

}  // namespace

CpuRankHalo::CpuRankHalo(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options,
                         const CpuRankParticles& particles)
    : ranks_(std::move(ranks)),
      options_(options),
      store_(particles.store),
      count_(particles.count),
      keep_(particles.keep),
      workers_(particles.workers),
      kernel_radius_(particles.kernel_radius),
      position_(particles.position),
      id_(particles.id),
      springs_(particles.springs),
      spring_candidates_(particles.spring_candidates),
      link_from_(particles.link_from),
      slabs_(ranks_->size()) {
  const auto array = [](const char* name, uint32_t size, ParticleArrayRole role) {
    return ParticleArraySpec{name, size, role, 1, nullptr, nullptr};
  };
  sort_key_ = store_.add_typed<uint64_t>(
      array(kArrayDistributedSortKey, sizeof(uint64_t), ParticleArrayRole::Carried));
  origin_ = store_.add_typed<uint32_t>(array(kArrayOrigin, sizeof(uint32_t), ParticleArrayRole::Sorted));
}

DistributedCounters CpuRankHalo::counters() const {
  DistributedCounters c = counters_;
  slabs_.describe(ranks_->rank(), c);
  return c;
}

bool CpuRankHalo::any(bool flag) const {
  int64_t lowered = flag ? 0 : 1;  // (an agreement reduces by min)
  sph::agree(*ranks_, &lowered);
  return lowered == 0;
}

void CpuRankHalo::agree() const { sph::agree(*ranks_); }

namespace {

float axis_coordinate(const Float4& p, int axis) { return slab_axis_coordinate(p.x, p.y, p.z, axis); }

}  // namespace

int32_t CpuRankHalo::layer(uint32_t i) const {
  const Float4& p = position_[i];
  return slab_layer(p.x, p.y, p.z, slabs_.axis(), 1.0f / kernel_radius_);
}

int32_t CpuRankHalo::sub_layer(uint32_t i) const {
  const Float4& p = position_[i];
  return slab_position(p.x, p.y, p.z, slabs_.axis(), 1.0f / kernel_radius_);
}

void CpuRankHalo::keep(size_t kept) {
  if (kept == count_) return;
  store_.permute(keep_.data(), kept, parallel());
  count_ = static_cast<uint32_t>(kept);
  store_.resize(count_);
}

void CpuRankHalo::rebalance(std::vector<int64_t>& held) {
  // Particles per rank, and the world's extent in cells (core/slab_rebalance.h).
  if (rebalance_slabs(*ranks_, slabs_, slabs_cut_, options_.rebalance_threshold, count_,
                      1.0f / kernel_radius_, held, [this](uint32_t i) { return position_[i]; })) {
    slabs_cut_ = true;
    ++counters_.rebalances;
  }
}

void CpuRankHalo::gather() {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const int size = t.size();
  PhaseClock clock(phase_times_);
  std::vector<RankBytes> out(static_cast<size_t>(size));
  sends_.resize(static_cast<size_t>(size));
  for (HostVector<uint32_t>& to : sends_) to.clear();
  // Every particle held between substeps is owned; a substep that failed after the ghosts came
  // and was rolled back leaves their marks in this (not carried) array.
  std::fill(origin_.data(), origin_.data() + count_, 0u);
  // This rank's slab, the sub-layers [slab_begin, slab_end) (int64: the outer slabs reach INT32_MIN
  // and INT32_MAX): a particle inside it needs no search of the cuts, nor, where the layers beside
  // and at its own lie inside it, any search for ghost destinations (the two per-particle loops
  // below cost about 1 ms a substep at 84,672 particles on one rank of the development VM with a
  // search for every particle).
  const int64_t slab_begin = slabs_.begin(me), slab_end = slabs_.end(me);
  // Migration: what another rank's slab holds goes there with every carried array.
  keep_.clear();
  for (uint32_t i = 0; i < count_; ++i) {
    const int32_t s = sub_layer(i);
    const int owner = s >= slab_begin && s < slab_end ? me : slabs_.owner(s);
    if (owner == me)
      keep_.push_back(i);
    else
      sends_[static_cast<size_t>(owner)].push_back(i);
  }
  for (int r = 0; r < size; ++r) pack(sends_[static_cast<size_t>(r)], out[static_cast<size_t>(r)]);
  std::vector<RankBytes> in = t.exchange(out);  // (an agreement: the substep so far, the packing)
  counters_.migrated_out += count_ - static_cast<uint32_t>(keep_.size());
  keep(keep_.size());
  for (int r = 0; r < size; ++r) counters_.migrated_in += unpack(in[static_cast<size_t>(r)], 0u);
  clock.lap(kHaloMigrate);
  const uint32_t owned = count_;
  // Ghosts: each owned particle goes to the other ranks whose slabs meet its layer or those beside.
  for (HostVector<uint32_t>& to : sends_) to.clear();
  for (uint32_t i = 0; i < owned; ++i) {
    const int32_t l = layer(i);
    if (slab_sublayer(l, -kSlabSubLayers) >= slab_begin &&
        slab_sublayer(l, 2 * kSlabSubLayers - 1) < slab_end)
      continue;  // the layers beside and at its own are this rank's alone
    int to[2];
    const int n = slabs_.ghost_destinations(l, me, to);
    for (int k = 0; k < n; ++k) sends_[static_cast<size_t>(to[k])].push_back(i);
  }
  for (int r = 0; r < size; ++r) pack(sends_[static_cast<size_t>(r)], out[static_cast<size_t>(r)]);
  in = t.exchange(out);  // (an agreement: the migrants' arrival, the ghosts' packing)
  for (int r = 0; r < size; ++r) unpack(in[static_cast<size_t>(r)], static_cast<uint32_t>(r) + 1u);
  clock.lap(kHaloGhosts);
  // Springs: the owned lists' partner ids to indices, the partners held nowhere here as spring
  // ghosts (cpu_halo_springs.cpp).
  if (springs_) gather_spring_partners(owned);
  counters_.ghosts = count_ - owned;
  clock.lap(kHaloSprings);
  // The world's grid: the extent and count of every rank's owned particles (what the undivided
  // world's grid sees).
  const float inv = 1.0f / kernel_radius_;
  int64_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  if (owned > 0) {
    // The extreme coordinates first, then their cells: cell_coordinate does not decrease with x
    // (a product, a flush of denormals, floor and a clamp, each monotone), so the cell of the
    // smallest x is the smallest cell, and one cell_coordinate an axis does the loop's work. (For
    // finite coordinates, which the owned particles have here: a substep that leaves one
    // non-finite rolls back before the next gather, and the API refuses them.)
    float xlo[3] = {position_[0].x, position_[0].y, position_[0].z}, xhi[3] = {xlo[0], xlo[1], xlo[2]};
    for (uint32_t i = 1; i < owned; ++i) {
      const float x[3] = {position_[i].x, position_[i].y, position_[i].z};
      for (int a = 0; a < 3; ++a) {
        xlo[a] = x[a] < xlo[a] ? x[a] : xlo[a];
        xhi[a] = x[a] > xhi[a] ? x[a] : xhi[a];
      }
    }
    for (int a = 0; a < 3; ++a) {
      lo[a] = cell_coordinate(xlo[a], inv);
      hi[a] = cell_coordinate(xhi[a], inv);
    }
  }
  // This rank's owned cells along the slabs' axis, and those of everything it holds (its table's
  // band; rank_grid_shape).
  const int axis = slabs_.axis();
  const int32_t first = static_cast<int32_t>(lo[axis]), last = static_cast<int32_t>(hi[axis]);
  int32_t held_first = first, held_last = last;
  if (count_ > owned) {
    float glo = axis_coordinate(position_[owned], axis), ghi = glo;
    for (uint32_t i = owned + 1; i < count_; ++i) {
      const float x = axis_coordinate(position_[i], axis);
      glo = x < glo ? x : glo;
      ghi = x > ghi ? x : ghi;
    }
    held_first = std::min(held_first, cell_coordinate(glo, inv));
    held_last = std::max(held_last, cell_coordinate(ghi, inv));
  }
  int64_t total = owned;
  agree();  // (the ghosts' arrival)
  t.all_min(lo, 3);
  t.all_max(hi, 3);
  t.all_sum(&total, 1);
  world_count_ = total;
  if (link_from_) {
    // The lowest id that waits for springs, over the ranks: every rank links in the same substep
    // (the linking exchanges its candidates), as the undivided world, whose word is the minimum.
    int64_t from = link_from_[0];
    t.all_min(&from, 1);
    link_from_[0] = static_cast<uint32_t>(from);
  }
  const bool any = total > 0;
  const CellCoord clo =
      any ? CellCoord{static_cast<int32_t>(lo[0]), static_cast<int32_t>(lo[1]), static_cast<int32_t>(lo[2])}
          : CellCoord{0, 0, 0};
  const CellCoord chi =
      any ? CellCoord{static_cast<int32_t>(hi[0]), static_cast<int32_t>(hi[1]), static_cast<int32_t>(hi[2])}
          : CellCoord{0, 0, 0};
  world_shape_ = make_grid_shape_for_extent(kernel_radius_, clo, chi, static_cast<uint32_t>(total));
  // The rank's own table: the world's cut to the band of cells it holds (none owned: the world's),
  // so that its size and the sort's passes over it follow what the rank holds (with the world's,
  // every rank cleared, summed and walked the world's 2 slots a particle each substep). The keys
  // stay the world's slots (after_sort), which every rank numbers alike.
  shape_ = rank_grid_shape(world_shape_, clo, chi, axis, first, last, held_first, held_last);
  own_table_ = shape_.nx != world_shape_.nx || shape_.ny != world_shape_.ny || shape_.nz != world_shape_.nz;
  clock.lap(kHaloExtent);
  order_visits();
  clock.lap(kHaloVisit);
}

void CpuRankHalo::after_sort(const CpuNeighborGrid& grid) {
  const GridView view = grid.view();
  uint64_t* key = sort_key_.data();
  // The key: the particle's slot in the world's table (where the rank's table is a band of the
  // world's, one cell a slot in both: the world's slot of that cell) and its place in the rank's
  // slot (the same place: the cell is complete here, its particles in the world's order).
  // (One cell a slot in the band: the slot's first particle names its cell.)
  for (uint32_t c = 0; c < view.shape.cell_count; ++c) {
    const uint32_t begin = view.cell_start[c], end = view.cell_start[c + 1];
    if (begin == end) continue;
    const uint64_t slot = own_table_ ? cell_hash_of_position(world_shape_, xyz(position_[begin])) : c;
    for (uint32_t i = begin; i < end; ++i) key[i] = (slot << 32) | (i - begin);
  }
  if (springs_) resolve_springs(grid.order().data());  // the spring lists' partners follow the sort
}

void CpuRankHalo::drop_ghosts() {
  if (springs_) springs_to_ids();  // before the ghosts go, whose indices the lists hold
  keep_.clear();
  for (uint32_t i = 0; i < count_; ++i)
    if (!ghost(i)) keep_.push_back(i);
  keep(keep_.size());
}

// ---- the backend's side: which of its values the ghosts take, and the step's inputs over the
// ranks.

void CpuBackend::attach_ranks(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options) {
  if (!ranks) throw Error(Status::Internal, "attach_ranks: no transport");
  if (count_ != 0 || rank_)
    throw Error(Status::Internal, "attach_ranks: the backend already holds particles");
  rank_ = std::make_unique<CpuRankHalo>(
      std::move(ranks), options,
      CpuRankParticles{store_, count_, keep_order_, workers_, config_.kernel_radius, position_, id_, springs_,
                       spring_candidates_, link_from_});
  // Springs across ranks (cpu_halo_springs.cpp): the lists name their partners by id through the
  // halo's steps, so no reorder may rewrite them as storage indices.
  if (springs_) springs_.array()->spec.rewrite_indices = nullptr;
}

DistributedCounters CpuBackend::distributed_counters() const {
  if (rank_) return rank_->counters();
  DistributedCounters c;  // (one slab, which holds every layer)
  c.slab_first = c.sub_first = INT32_MIN;
  c.slab_last = c.sub_last = INT32_MAX;
  return c;
}

void CpuBackend::rethrow_step_failure() const {
  if (rank_) rethrow_agreed(rank_->transport());
  throw;
}

// The next step's inputs over the ranks: the largest speed and acceleration, and with DFSPH's depth
// limit the world's height span (its lowest point as the largest of -lo), over the owned particles
// (every particle held between substeps is owned), in one reduction. min and max are exact: every
// rank takes the undivided world's H, bit for bit. `span` is this rank's own, measured by the caller
// before the agreement that precedes this call: the measurement allocates (the reduction's
// partials), and a rank that fails there must meet the others at that agreement, never at this
// all_max (core/rank_agreement.h).
void CpuBackend::reduce_step_inputs(const HeightSpan& span) {
  float maxima[4] = {max_speed_, max_acceleration_, 0.0f, 0.0f};
  const bool depth = depth_limit_on();
  if (depth) {
    maxima[2] = -span.lo;
    maxima[3] = span.hi;
  }
  rank_->transport().all_max(maxima, depth ? 4 : 2);
  max_speed_ = maxima[0];
  max_acceleration_ = maxima[1];
  fluid_height_ = depth ? height_of_span(-maxima[2], maxima[3]) : 0.0f;
}

void CpuBackend::halo_begin_frame() {
  std::vector<int64_t> held(static_cast<size_t>(rank_->transport().size()), 0);
  const HeightSpan span = own_height_span();
  rank_->agree();  // (the frame's start: the step's code before it ran on each rank alone)
  reduce_step_inputs(span);
  rank_->rebalance(held);
}

void CpuBackend::halo_share_density() {
  using Record = HaloDensityRecord;
  rank_->share<Record>(
      "densities",
      [this](uint32_t i) {
        return Record{id_[i], density_[i], position_[i].w, velocity_[i].w, neighbors_[i]};
      },
      [this](uint32_t i, const Record& r) {
        density_[i] = r.density;
        position_[i].w = r.pressure;
        velocity_[i].w = r.inv_density;
        neighbors_[i] = r.neighbors;
        columns_.set_density(i, r.pressure, r.inv_density);
        columns_.set_neighbor_count(i, r.neighbors);
      });
}

void CpuBackend::halo_share_normals() {
  using Record = HaloNormalRecord;
  rank_->share<Record>(
      "colour normals",
      [this](uint32_t i) {
        return Record{id_[i], {0u, 0u, 0u}, normals_[i]};
      },
      [this](uint32_t i, const Record& r) {
        normals_[i] = r.normal;
        columns_.set_normal(i, r.normal);
      });
}

uint32_t CpuBackend::halo_end_substep(uint32_t bad_id) {
  rank_->drop_ghosts();
  const RankTransport& t = rank_->transport();
  int64_t bad = bad_id;
  const HeightSpan span = own_height_span();
  agree(t, &bad);  // (the force and integration passes)
  reduce_step_inputs(span);
  if (bad != static_cast<int64_t>(kAllFinite) && bad_id == kAllFinite) {
    // Another rank's particle: that rank's message classifies it.
    non_finite_ = NonFiniteFailure{};
    non_finite_.count = 1;
    non_finite_.ids.push_back(static_cast<uint32_t>(bad));
  }
  return static_cast<uint32_t>(bad);
}

}  // namespace sph
