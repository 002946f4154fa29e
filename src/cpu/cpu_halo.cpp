// SPDX-License-Identifier: MIT
// The CPU backend as one rank of a distributed world (include/sph_mpi.h, docs/distributed.md):
// host-staged halos over a RankTransport (MPI in libsph_mpi). A substep of a rank runs the
// single world's passes over its own particles plus ghosts, with four steps of its own:
//   before the sort   particles that left the slab migrate to their owner (every carried
//                     array), the ghosts arrive (the owned particles of the cell layer beside
//                     the slab), the world's grid shape is reduced from every rank's extent;
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
// Each place where the ranks meet after code that can fail (an allocation, a crowded cell) is
// an agreement (core/rank_agreement.h): a rank that failed joins the others' next one from its
// catch block (rethrow_step_failure), and every rank returns the error instead of waiting.
// The sort takes particles in key order, so each cell's particles come in the order the
// undivided world's stable sort gives them: the neighbour sums add in the same order and a
// distributed world steps the single world's bits (while the grid's table covers the
// particles' extent without folding; docs/distributed.md).
#include <algorithm>
#include <cstring>
#include <memory>
#include <string>

#include "../core/grid_layout.h"
#include "../core/halo_records.h"
#include "../core/rank_agreement.h"
#include "../core/slab_rebalance.h"
#include "cpu_halo_share.h"

namespace sph {

namespace {

constexpr const char* kArrayOrigin = "distributed_origin";

}  // namespace

void CpuBackend::attach_ranks(std::shared_ptr<const RankTransport> ranks, const DistributedOptions& options) {
  if (!ranks) throw Error(Status::Internal, "attach_ranks: no transport");
  if (count_ != 0 || ranks_)
    throw Error(Status::Internal, "attach_ranks: the backend already holds particles");
  const auto array = [](const char* name, uint32_t size, ParticleArrayRole role) {
    return ParticleArraySpec{name, size, role, 1, nullptr, nullptr};
  };
  sort_key_ = store_.add_typed<uint64_t>(
      array(kArrayDistributedSortKey, sizeof(uint64_t), ParticleArrayRole::Carried));
  origin_ = store_.add_typed<uint32_t>(array(kArrayOrigin, sizeof(uint32_t), ParticleArrayRole::Sorted));
  distributed_options_ = options;
  slabs_ = SlabDecomposition(ranks->size());
  ranks_ = std::move(ranks);
  // Springs across ranks (cpu_halo_springs.cpp): the lists name their partners by id through the
  // halo's steps, so no reorder may rewrite them as storage indices.
  if (springs_) springs_.array()->spec.rewrite_indices = nullptr;
}

DistributedCounters CpuBackend::distributed_counters() const {
  DistributedCounters c = halo_counters_;
  c.axis = slabs_.axis();
  const int me = ranks_ ? ranks_->rank() : 0;
  const std::vector<int32_t>& cuts = slabs_.cuts();
  c.slab_first = me == 0 ? INT32_MIN : cuts[static_cast<size_t>(me - 1)];
  c.slab_last = me == static_cast<int>(cuts.size()) ? INT32_MAX : cuts[static_cast<size_t>(me)] - 1;
  return c;
}

bool CpuBackend::halo_any(bool flag) const {
  int64_t lowered = flag ? 0 : 1;  // (an agreement reduces by min)
  agree(*ranks_, &lowered);
  return lowered == 0;
}

void CpuBackend::halo_agree() const { agree(*ranks_); }

void CpuBackend::rethrow_step_failure() const {
  if (ranks_) rethrow_agreed(*ranks_);
  throw;
}

int32_t CpuBackend::halo_layer(uint32_t i) const {
  const Float4& p = position_[i];
  return slab_layer(p.x, p.y, p.z, slabs_.axis(), 1.0f / config_.kernel_radius);
}

bool CpuBackend::halo_travels(const ParticleArraySpec& spec) {
  if (spec.elements_per_particle == 0) return false;
  // RK4's stage state lives through a substep, and a particle may change ranks between its stages.
  return spec.role == ParticleArrayRole::Carried || std::strcmp(spec.name, kArrayRk4Start) == 0 ||
         std::strcmp(spec.name, kArrayRk4Sum) == 0;
}

void CpuBackend::halo_pack(uint32_t i, RankBytes& out) const {
  for (const auto& a : store_.arrays()) {
    if (!halo_travels(a->spec)) continue;
    const size_t bytes = particle_bytes(a->spec);
    const unsigned char* from = a->bytes.data() + i * bytes;
    out.insert(out.end(), from, from + bytes);
  }
}

uint32_t CpuBackend::halo_unpack(const RankBytes& in, uint32_t origin) {
  size_t record = 0;
  for (const auto& a : store_.arrays())
    if (halo_travels(a->spec)) record += particle_bytes(a->spec);
  if (in.size() % record != 0) throw Error(Status::Internal, "halo: a rank sent a partial particle record");
  const uint32_t n = static_cast<uint32_t>(in.size() / record);
  if (n == 0) return 0;
  const uint32_t first = count_;
  store_.resize(static_cast<size_t>(first) + n);
  const unsigned char* from = in.data();
  for (uint32_t k = 0; k < n; ++k)
    for (const auto& a : store_.arrays()) {
      if (!halo_travels(a->spec)) continue;
      const size_t bytes = particle_bytes(a->spec);
      std::memcpy(a->bytes.data() + (first + k) * bytes, from, bytes);
      from += bytes;
    }
  for (uint32_t k = 0; k < n; ++k) origin_[first + k] = origin;
  count_ = first + n;
  return n;
}

void CpuBackend::halo_keep(size_t kept) {
  if (kept == count_) return;
  store_.permute(keep_order_.data(), kept, parallel());
  count_ = static_cast<uint32_t>(kept);
  store_.resize(count_);
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
  ranks_->all_max(maxima, depth ? 4 : 2);
  max_speed_ = maxima[0];
  max_acceleration_ = maxima[1];
  fluid_height_ = depth ? height_of_span(-maxima[2], maxima[3]) : 0.0f;
}

void CpuBackend::halo_begin_frame() {
  const RankTransport& t = *ranks_;
  std::vector<int64_t> held(static_cast<size_t>(t.size()), 0);
  const HeightSpan span = own_height_span();
  halo_agree();  // (the frame's start: the step's code before it ran on each rank alone)
  reduce_step_inputs(span);
  // Particles per rank, and the world's extent in cells (core/slab_rebalance.h).
  if (rebalance_slabs(t, slabs_, slabs_cut_, distributed_options_.rebalance_threshold, count_,
                      1.0f / config_.kernel_radius, held, [this](uint32_t i) { return position_[i]; })) {
    slabs_cut_ = true;
    ++halo_counters_.rebalances;
  }
}

void CpuBackend::halo_gather() {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const int size = t.size();
  std::vector<RankBytes> out(static_cast<size_t>(size));
  // Every particle held between substeps is owned; a substep that failed after the ghosts came
  // and was rolled back leaves their marks in this (not carried) array.
  std::fill(origin_.data(), origin_.data() + count_, 0u);
  // Migration: what another rank's slab holds goes there with every carried array.
  keep_order_.clear();
  for (uint32_t i = 0; i < count_; ++i) {
    const int owner = slabs_.owner(halo_layer(i));
    if (owner == me)
      keep_order_.push_back(i);
    else
      halo_pack(i, out[static_cast<size_t>(owner)]);
  }
  std::vector<RankBytes> in = t.exchange(out);  // (an agreement: the substep so far, the packing)
  halo_counters_.migrated_out += count_ - static_cast<uint32_t>(keep_order_.size());
  halo_keep(keep_order_.size());
  for (int r = 0; r < size; ++r) halo_counters_.migrated_in += halo_unpack(in[static_cast<size_t>(r)], 0u);
  const uint32_t owned = count_;
  // Ghosts: each owned particle of a layer beside another rank's slab goes to that rank.
  for (RankBytes& b : out) b.clear();
  for (uint32_t i = 0; i < owned; ++i) {
    int to[2];
    const int n = slabs_.ghost_destinations(halo_layer(i), me, to);
    for (int k = 0; k < n; ++k) halo_pack(i, out[static_cast<size_t>(to[k])]);
  }
  in = t.exchange(out);  // (an agreement: the migrants' arrival, the ghosts' packing)
  for (int r = 0; r < size; ++r) halo_unpack(in[static_cast<size_t>(r)], static_cast<uint32_t>(r) + 1u);
  // Springs: the owned lists' partner ids to indices, the partners held nowhere here as spring
  // ghosts (cpu_halo_springs.cpp).
  if (springs_) halo_gather_spring_partners(owned);
  halo_counters_.ghosts = count_ - owned;
  // The world's grid: the extent and count of every rank's owned particles (what the undivided
  // world's grid sees).
  const float inv = 1.0f / config_.kernel_radius;
  int64_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  for (uint32_t i = 0; i < owned; ++i) {
    const float x[3] = {position_[i].x, position_[i].y, position_[i].z};
    for (int a = 0; a < 3; ++a) {
      const int64_t c = cell_coordinate(x[a], inv);
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
  int64_t total = owned;
  halo_agree();  // (the ghosts' arrival)
  t.all_min(lo, 3);
  t.all_max(hi, 3);
  t.all_sum(&total, 1);
  halo_world_count_ = total;
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
  halo_shape_ = make_grid_shape_for_extent(config_.kernel_radius, clo, chi, static_cast<uint32_t>(total));
  // The sort's order: by key, then id (two keys are equal only where the table folds).
  halo_visit_.resize(count_);
  for (uint32_t i = 0; i < count_; ++i) halo_visit_[i] = i;
  const uint64_t* key = sort_key_.data();
  const uint32_t* id = id_.data();
  std::sort(halo_visit_.begin(), halo_visit_.end(),
            [key, id](uint32_t a, uint32_t b) { return key[a] != key[b] ? key[a] < key[b] : id[a] < id[b]; });
}

void CpuBackend::halo_keys() {
  const GridView view = grid_.view();
  uint64_t* key = sort_key_.data();
  for (uint32_t c = 0; c < view.shape.cell_count; ++c)
    for (uint32_t i = view.cell_start[c]; i < view.cell_start[c + 1]; ++i)
      key[i] = (static_cast<uint64_t>(c) << 32) | (i - view.cell_start[c]);
  if (springs_) halo_resolve_springs();  // the spring lists' partners follow the sort
}

void CpuBackend::halo_share_density() {
  using Record = HaloDensityRecord;
  halo_share<Record>(
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
  halo_share<Record>(
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
  if (springs_) halo_springs_to_ids();  // before the ghosts go, whose indices the lists hold
  keep_order_.clear();
  for (uint32_t i = 0; i < count_; ++i)
    if (!ghost(i)) keep_order_.push_back(i);
  halo_keep(keep_order_.size());
  const RankTransport& t = *ranks_;
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
