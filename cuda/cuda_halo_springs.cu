// SPDX-License-Identifier: MIT
// Springs across the ranks of a distributed CUDA world (SPH_FEATURE_SPRINGS; the physics is
// src/physics/springs.h, the device's steps cuda/device_halo_springs.cu, the halo cuda_halo.cu).
// The CPU rank's steps (src/cpu/cpu_halo_springs.cpp), at the same points of the substep, with
// the same exchanges and the same order of what crosses:
//   between substeps    the lists name their partners by id (a rank's particles reorder on their
//                       own; no compaction rewrites them: the ghosts' drop and a sink's move them
//                       as words, enqueue_spring_compact's partner_ids)
//   before the sort     (halo_gather_spring_partners, once the ghosts are in) the owned lists' ids
//                       become storage indices (a table of the held ids sorted by CUB, a binary
//                       search a partner); the partners held nowhere here come from their owners
//                       as spring ghosts: their ids (ascending, unique, found on the device) go to
//                       every rank, each rank gathers the particles it owns of them by a device list
//                       (DeviceHalo::pack) and they are appended with origin ranks + r, which
//                       DeviceHalo::enqueue_mark keeps out of the density records' lists (a spring
//                       ghost is two layers or more from the slab: no neighbour walk of an owned
//                       particle reaches it). An id no rank holds is a particle a sink removed: the
//                       spring is dropped (partner kNoSpring, rest 0), as the undivided rewrite does.
//                       The device's link_from word comes down here, and the lowest over the ranks
//                       goes back up after the ghosts' agreement (halo_agree_link_from): every rank
//                       links in the same substep, as the undivided world;
//   after the sort      the reorder moves the owned lists' partners by the sort's inverse
//                       (enqueue_spring_reorder; a ghost's list is left in ids);
//   linking             pass 1 runs on the owned particles, whose neighbour cells are complete; the
//                       ghosts take their owners' candidates (HaloSpringCandidateRecord, 68 bytes,
//                       through halo_refresh's lists) as ids, found among the sorted particles
//                       (kSpringCandidateElsewhere when not held); pass 2 links the owned particles;
//   the substep's end   (halo_springs_to_ids, in halo_drop_ghosts) indices back to ids before the
//                       ghosts go, also between RK4's stages and before a sink's compaction.
#include <cstring>
#include <vector>

#include "cuda_backend_impl.h"

namespace sph {

uint32_t CudaBackend::halo_gather_spring_partners(uint32_t owned, uint32_t n) {
  const RankTransport& t = *ranks_;
  const size_t size = static_cast<size_t>(t.size());
  const int me = t.rank();
  cudaStream_t s = r_->stream;
  DeviceHaloSprings& hs = *r_->halo_springs;
  DeviceHalo& h = *r_->halo;
  const ParticleArrays& a = r_->store->arrays();
  // The link word first (it is read after the ghosts' agreement: halo_agree_link_from).
  cuda_check(cudaMemcpyAsync(hs.host_word(), a.link_from, sizeof(uint32_t), cudaMemcpyDeviceToHost, s),
             "copy of the spring link word");
  // The owned lists' partner ids to the indices of the particles held now (owned and ghosts);
  // those held nowhere here wait, their ids aside, for the spring ghosts.
  hs.index_ids(a.id, n, s);
  uint32_t waiting = 0;
  const uint32_t* wanted = hs.index_owned_lists(a.springs, owned, &waiting, s);  // (waits)
  halo_springs_indexed_ = true;  // (halo_springs_to_ids turns them back before the ghosts go)
  RankBytes ids(sizeof(uint32_t) * waiting);
  if (waiting > 0) std::memcpy(ids.data(), wanted, ids.size());
  std::vector<RankBytes> out(size);
  for (size_t r = 0; r < size; ++r)
    if (static_cast<int>(r) != me) out[r] = ids;
  std::vector<RankBytes> in = t.exchange(out);  // (an agreement: the ghosts' arrival, the wants)
  // What this rank owns of each rank's wants, in the wanted (ascending id) order.
  const HostVector<HaloArray> arrays = halo_arrays();
  size_t record = 0;
  for (const HaloArray& x : arrays) record += x.bytes;
  HostVector<uint32_t> asked;
  for (size_t r = 0; r < size; ++r) {
    out[r].clear();
    const uint32_t m = static_cast<uint32_t>(in[r].size() / sizeof(uint32_t));
    if (m == 0) continue;
    asked.resize(m);
    std::memcpy(asked.data(), in[r].data(), sizeof(uint32_t) * m);
    uint32_t found = 0;
    const uint32_t* list = hs.find_owned(asked.data(), m, owned, &found, s);
    if (found == 0) continue;
    const unsigned char* host = h.pack(arrays.data(), static_cast<int>(arrays.size()), list, found, s);
    out[r].assign(host, host + record * found);
  }
  in = t.exchange(out);  // (an agreement: the spring ghosts' packing)
  for (size_t r = 0; r < size; ++r) {
    const uint32_t m = halo_receive(in[r], n);
    h.enqueue_origin(n, m, static_cast<uint32_t>(size + r), s);
    n += m;
  }
  if (waiting > 0) {
    // The waiting partners: a spring ghost's index, or none (a sink removed the partner).
    hs.index_ids(a.id, n, s);
    hs.resolve_waiting(a.springs, owned, s);
  }
  // (The link word is read after the ghosts' agreement, where nothing may fail on one rank alone.)
  cuda_check(cudaStreamSynchronize(s), "the spring partners");
  return n;
}

void CudaBackend::halo_agree_link_from() {
  // The lowest id that waits for springs, over the ranks (the word came down in
  // halo_gather_spring_partners): every rank links in the same substep, and the linking
  // exchanges its candidates (halo_share_spring_candidates).
  uint32_t* word = r_->halo_springs->host_word();
  int64_t from = *word;
  ranks_->all_min(&from, 1);
  *word = static_cast<uint32_t>(from);
  halo_linking_ = *word != kNoPendingLinks;
  // (The pinned word is not written again before the stream's next wait.)
  cuda_check(cudaMemcpyAsync(r_->store->arrays().link_from, word, sizeof(uint32_t), cudaMemcpyHostToDevice,
                             r_->stream),
             "copy of the spring link word");
}

void CudaBackend::halo_share_spring_candidates(cudaStream_t stream) {
  if (!halo_linking_) return;  // (the device's pass 1 found the word empty and listed none)
  halo_linking_ = false;       // (the pass clears the word: RK4's later stages do not link)
  const ParticleArrays& a = r_->store->arrays();
  const uint32_t n = halo_owned_ + halo_ghosts_;
  halo_refresh<HaloSpringCandidateRecord>(stream, "spring candidates", a);
  DeviceHaloSprings& hs = *r_->halo_springs;
  hs.index_ids(a.sorted_id, n, stream);
  hs.candidates_to_indices(a.spring_candidates, a.halo_ghost, n, stream);
}

void CudaBackend::halo_springs_to_ids() {
  // (RK4 ends each stage as a substep does, and the frame loop drops the ghosts again: once is the
  // change.)
  if (!halo_springs_indexed_) return;
  halo_springs_indexed_ = false;
  const ParticleArrays& a = r_->store->arrays();
  r_->halo_springs->enqueue_to_ids(a.springs, a.sorted_id, a.halo_ghost, halo_owned_ + halo_ghosts_,
                                   r_->stream);
}

}  // namespace sph
