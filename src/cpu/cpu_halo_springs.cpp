// SPDX-License-Identifier: MIT
// Springs across the ranks of a distributed world (SPH_FEATURE_SPRINGS on the CPU rank,
// CpuRankHalo of cpu_rank_halo.h; the physics is src/physics/springs.h, the halo
// src/cpu/cpu_halo.cpp; docs/distributed.md).
//
// A spring is stored on both of its particles, each list naming the partner. The undivided
// world names it by storage index and rewrites the lists at every reorder; a rank's particles
// reorder on their own (migration, ghosts arriving and leaving), so outside the sorted part of a
// substep a rank's lists name their partners by id instead, and no reorder rewrites them
// (attach_ranks clears the array's rewrite):
//   before the sort  (gather_spring_partners, once the ghosts are in) the owned lists' ids
//                    become storage indices (a hash table of the ids held); each partner that is
//                    neither owned here nor a ghost comes from its owner as a spring ghost: an
//                    elastic spring has no longest length, so its far end may be past the halo,
//                    one cell layer deep. One exchange of the wanted ids (to every rank), one of
//                    the particles (pack's records). A spring ghost is in no neighbour walk
//                    of an owned particle (its cell layer is two or more from the slab) and
//                    takes no density record; the spring force reads its position and velocity,
//                    which are its owner's at the substep's start. An id held by no rank is a
//                    particle a sink removed, and the spring is dropped (partner kNoSpring, rest
//                    0), as the undivided world's rewrite drops it at the removal;
//   after the sort   (resolve_springs) the partners follow the sort's permutation;
//   linking          (spring_pass) pass 1 runs on the owned particles, whose neighbour cells are
//                    complete; the ghosts take their owners' candidates (ids, as local indices,
//                    share_spring_candidates); pass 2 links the owned particles. Every rank
//                    links in the same substep: the lowest waiting id is the minimum over the
//                    ranks (gather);
//   the end          (springs_to_ids) indices back to ids, before the ghosts are dropped.
// Each end of a spring lives on its owner, which computes the same distance bit for bit as the
// undivided world from the same positions, in the same slot order: the spring accelerations,
// the rest lengths' flow and the dropped springs are the undivided world's, bit for bit.
#include <algorithm>
#include <cstring>
#include <vector>

#include "../core/halo_records.h"
#include "cpu_halo_share.h"

namespace sph {

namespace {

// A ghost's link candidate that this rank does not hold: no owned particle, so no match in
// spring_link, and not kNoSpring, which ends a candidate list.
constexpr uint32_t kCandidateElsewhere = kNoSpring - 1u;
// A partner no particle here has until the spring ghosts arrive (its id kept in missing_).
constexpr uint32_t kPartnerPending = kNoSpring - 1u;

static_assert(sizeof(HaloSpringCandidateRecord::candidate) == sizeof(uint32_t) * kSpringSlots,
              "a candidates' record holds kSpringSlots ids");

RankBytes id_bytes(const std::vector<uint32_t>& ids) {
  RankBytes b(ids.size() * sizeof(uint32_t));
  if (!ids.empty()) std::memcpy(b.data(), ids.data(), b.size());
  return b;
}

}  // namespace

void CpuRankHalo::index_ids() {
  id_table_.reset(count_);
  for (uint32_t i = 0; i < count_; ++i) id_table_.insert(id_[i], i);
}

void CpuRankHalo::gather_spring_partners(uint32_t owned) {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const int size = t.size();
  // The owned lists' partner ids to the indices of the particles held now (owned and ghosts);
  // those held nowhere here wait, their ids aside, for the spring ghosts.
  index_ids();
  missing_.assign(static_cast<size_t>(owned) * kSpringSlots, kNoSpring);
  SpringList* lists = springs_.data();
  uint32_t* missing = missing_.data();
  const CpuIdTable& table = id_table_;
  parallel().for_each(owned, [&](uint32_t i) {
    SpringList& l = lists[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      const uint32_t p = l.partner[k];
      if (p == kNoSpring) continue;
      const uint32_t j = table.find(p);
      if (j != CpuIdTable::kAbsent) {
        l.partner[k] = j;
      } else {
        missing[static_cast<size_t>(i) * kSpringSlots + k] = p;
        l.partner[k] = kPartnerPending;
      }
    }
  });
  springs_indexed_ = true;  // (springs_to_ids turns them back at the substep's end)
  std::vector<uint32_t> wanted;
  for (size_t e = 0; e < missing_.size(); ++e)
    if (missing[e] != kNoSpring) wanted.push_back(missing[e]);
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  std::vector<RankBytes> out(static_cast<size_t>(size));
  for (int r = 0; r < size; ++r)
    if (r != me) out[static_cast<size_t>(r)] = id_bytes(wanted);
  std::vector<RankBytes> in = t.exchange(out);  // (an agreement: the ghosts' arrival, the wants)
  // What this rank owns of each rank's wants, in the wanted (ascending id) order.
  sends_.resize(static_cast<size_t>(size));
  for (int r = 0; r < size; ++r) {
    HostVector<uint32_t>& which = sends_[static_cast<size_t>(r)];
    which.clear();
    const RankBytes& asked = in[static_cast<size_t>(r)];
    for (size_t k = 0; k + sizeof(uint32_t) <= asked.size(); k += sizeof(uint32_t)) {
      uint32_t id;
      std::memcpy(&id, asked.data() + k, sizeof id);
      const uint32_t j = table.find(id);
      if (j != CpuIdTable::kAbsent && j < owned) which.push_back(j);
    }
    pack(which, out[static_cast<size_t>(r)]);
  }
  in = t.exchange(out);  // (an agreement: the spring ghosts' packing)
  const uint32_t first = count_;
  for (int r = 0; r < size; ++r)
    unpack(in[static_cast<size_t>(r)], static_cast<uint32_t>(size) + static_cast<uint32_t>(r) + 1u);
  if (wanted.empty()) return;
  // The waiting partners: a spring ghost's index, or none (a sink removed the partner: the
  // spring is dropped, as the undivided world's rewrite drops it at the removal).
  std::vector<uint64_t> arrived(count_ - first);
  for (uint32_t i = first; i < count_; ++i) arrived[i - first] = (static_cast<uint64_t>(id_[i]) << 32) | i;
  std::sort(arrived.begin(), arrived.end());
  lists = springs_.data();  // (the arrivals resized the store)
  parallel().for_each(owned, [&](uint32_t i) {
    SpringList& l = lists[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      if (l.partner[k] != kPartnerPending) continue;
      const uint32_t id = missing[static_cast<size_t>(i) * kSpringSlots + k];
      const auto at = std::lower_bound(arrived.begin(), arrived.end(), static_cast<uint64_t>(id) << 32);
      const bool found = at != arrived.end() && (*at >> 32) == id;
      l.partner[k] = found ? static_cast<uint32_t>(*at & 0xffffffffu) : kNoSpring;
      if (!found) l.rest[k] = 0.0f;
    }
  });
}

void CpuRankHalo::resolve_springs(const uint32_t* order) {
  // The sort moved every particle (store_.permute, which rewrites no spring list in a distributed
  // world): the owned lists' partners follow it.
  inverse_.resize(count_);
  uint32_t* inverse = inverse_.data();
  for (uint32_t i = 0; i < count_; ++i) inverse[order[i]] = i;
  SpringList* lists = springs_.data();
  parallel().for_each(count_, [&](uint32_t i) {
    if (ghost(i)) return;  // (a ghost's list is its owner's to use)
    SpringList& l = lists[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k)
      if (l.partner[k] != kNoSpring) l.partner[k] = inverse[l.partner[k]];
  });
}

void CpuRankHalo::springs_to_ids() {
  // (RK4 ends each stage as a substep, and the frame loop the substep again: once is the change.)
  if (!springs_indexed_) return;
  springs_indexed_ = false;
  SpringList* lists = springs_.data();
  const uint32_t* ids = id_.data();
  parallel().for_each(count_, [&](uint32_t i) {
    if (ghost(i)) return;
    SpringList& l = lists[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k)
      if (l.partner[k] != kNoSpring) l.partner[k] = ids[l.partner[k]];
  });
}

void CpuRankHalo::share_spring_candidates() {
  using Record = HaloSpringCandidateRecord;
  index_ids();  // (the sorted order's indices)
  uint32_t* candidates = spring_candidates_.data();
  share<Record>(
      "spring candidates",
      [&](uint32_t i) {
        Record r;
        r.id = id_[i];
        const uint32_t* mine = candidates + static_cast<size_t>(i) * kSpringSlots;
        for (uint32_t k = 0; k < kSpringSlots; ++k)
          r.candidate[k] = mine[k] == kNoSpring ? kNoSpring : id_[mine[k]];
        return r;
      },
      [&](uint32_t i, const Record& r) {
        uint32_t* theirs = candidates + static_cast<size_t>(i) * kSpringSlots;
        for (uint32_t k = 0; k < kSpringSlots; ++k) {
          if (r.candidate[k] == kNoSpring) {
            theirs[k] = kNoSpring;
            continue;
          }
          const uint32_t j = id_table_.find(r.candidate[k]);
          theirs[k] = j == CpuIdTable::kAbsent ? kCandidateElsewhere : j;
        }
      });
}

}  // namespace sph
