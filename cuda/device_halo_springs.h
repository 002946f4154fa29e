// SPDX-License-Identifier: MIT
// The device side of springs across a distributed CUDA rank (cuda_halo_springs.cu drives it; the
// CPU rank's steps are src/cpu/cpu_halo_springs.cpp). Between substeps a rank's spring lists name
// their partners by id; inside a substep the owned lists hold storage indices. The ids held are
// found through a table of (id, index) pairs sorted by id (a CUB radix sort, then a binary search
// per lookup): no hash table, and the same table serves every lookup of a substep:
//   index_ids            the table of particles [0, n) (their ids, storage order)
//   index_owned_lists    the owned lists' ids to indices; the partners held nowhere here wait
//                        (kPartnerPending, their ids aside) and their ids, ascending and unique,
//                        reach the host (only those: nothing per particle is downloaded)
//   find_owned           of the ids another rank wants, the owned particles that hold them (a
//                        device list for DeviceHalo::pack)
//   resolve_waiting      once the spring ghosts are in (and indexed): the waiting partners to
//                        their indices, or dropped (a sink removed the partner)
//   enqueue_to_ids       the sorted owned lists back to ids (before the ghosts go)
//   candidates_to_indices linking: the ghosts' candidates (ids, from their owners' records) to
//                        indices of the sorted particles, kCandidateElsewhere when not held
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/physics/springs.h"
#include "device_array.h"

namespace sph {

// A partner no particle here has until the spring ghosts arrive (its id kept aside), and a ghost's
// link candidate this rank does not hold (no owned particle matches it in spring_link; not
// kNoSpring, which ends a candidate list). The CPU rank's values (cpu_halo_springs.cpp).
constexpr uint32_t kSpringPartnerPending = kNoSpring - 1u;
constexpr uint32_t kSpringCandidateElsewhere = kNoSpring - 1u;

class DeviceHaloSprings {
 public:
  // Its set-up runs on `stream` (the world's) and is waited for here.
  DeviceHaloSprings(uint32_t capacity, cudaStream_t stream);

  // The table: ids[0, n) (device) with their indices, sorted by id (enqueued).
  void index_ids(const uint32_t* ids, uint32_t n, cudaStream_t stream);
  // lists[0, owned) (ids) to indices through the table; the partners it lacks wait. Returns the
  // waiting ids, ascending, each once (pinned, *count of them; valid until the next call). Waits.
  const uint32_t* index_owned_lists(SpringList* lists, uint32_t owned, uint32_t* count, cudaStream_t stream);
  // Of asked[0, m) (host, any order), the table's particles below `owned` holding them, in the asked
  // order: a device list of *found indices (valid until the next call). Waits.
  const uint32_t* find_owned(const uint32_t* asked, uint32_t m, uint32_t owned, uint32_t* found,
                             cudaStream_t stream);
  // After index_ids over the particles with the spring ghosts: lists[0, owned)'s waiting partners
  // to their indices, or dropped (kNoSpring, rest 0) when no particle holds them (enqueued).
  void resolve_waiting(SpringList* lists, uint32_t owned, cudaStream_t stream);
  // lists[0, n) (sorted order; ghost[i]: a ghost's list, left alone): partners to sorted_id's ids.
  void enqueue_to_ids(SpringList* lists, const uint32_t* sorted_id, const uint32_t* ghost, uint32_t n,
                      cudaStream_t stream) const;
  // After index_ids over the sorted ids: the ghosts' candidates (ids) to the table's indices.
  void candidates_to_indices(uint32_t* candidates, const uint32_t* ghost, uint32_t n,
                             cudaStream_t stream) const;

  // One pinned word for the host's reads and writes of the device's link_from.
  uint32_t* host_word() const { return host_word_.get(); }
  uint64_t bytes() const;

 private:
  void ensure_temp(size_t bytes);
  void ensure_asked(uint32_t m);

  uint32_t capacity_;
  uint32_t table_n_ = 0;
  DeviceArray<uint32_t> iota_, table_ids_, table_idx_;
  DeviceArray<uint32_t> missing_;        // kSpringSlots a particle: the waiting partners' ids, else kNoSpring
  DeviceArray<uint32_t> wanted_;         // kSpringSlots a particle: the waiting ids, then unique
  DeviceArray<uint32_t> wanted_sorted_;  // grows on demand
  size_t wanted_sorted_count_ = 0;
  DeviceArray<uint32_t> asked_, asked_idx_, found_;  // grow on demand
  DeviceArray<unsigned char> asked_flags_;
  size_t asked_count_ = 0;
  DeviceArray<uint64_t> words_;  // selected counts (64-bit: 16 entries a particle)
  DeviceArray<unsigned char> temp_;
  size_t temp_bytes_ = 0;
  PinnedArray<uint64_t> host_words_;
  PinnedArray<uint32_t> host_ids_;  // grows on demand
  size_t host_ids_count_ = 0;
  PinnedArray<uint32_t> host_word_;
};

}  // namespace sph
