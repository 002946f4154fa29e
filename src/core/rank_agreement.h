// SPDX-License-Identifier: MIT
// Failures agreed between the ranks of a distributed world. A rank that fails on its own (an
// allocation, a crowded cell, a file it cannot read) must not leave the others waiting in the
// next collective call: every place where ranks meet after code that can fail is an agreement,
// and every agreement has one shape, an all_min of one int64, so a failed rank meets the others
// at whichever agreement they reach next (rethrow_agreed), whatever its own code was doing. The
// first failing rank's error then goes to every rank (one broadcast, on failure only).
#pragma once

#include <stdint.h>

#include <string>

#include "rank_transport.h"
#include "status.h"

namespace sph {

// A failure every rank knows of: thrown on every rank once an agreement found that one failed
// (the failing ranks their own status and message, the others the first failing rank's, the
// message prefixed with "rank r: "). Never joined again.
class AgreedRankFailure : public Error {
 public:
  using Error::Error;
};

// COLLECTIVE. One agreement of ranks that have not failed. Each rank contributes `*payload`
// (>= 0, below 2^62), reduced by min over the ranks into *payload, so an agreement can carry a
// flag or an id the ranks reduce anyway. Throws AgreedRankFailure when a rank failed.
void agree(const RankTransport& ranks, int64_t* payload);
inline void agree(const RankTransport& ranks) {
  int64_t none = 0;
  agree(ranks, &none);
}

// COLLECTIVE, among ranks that have not failed. same[k]: whether values[k] is the same on every
// rank, for k < n <= 4 (two all-reduces of n int64): how the ranks compare what must match (a
// frame's inputs, a world's backend, a checkpoint's path) before they act on it.
void compare_over_ranks(const RankTransport& ranks, const int64_t* values, int n, bool* same);

// COLLECTIVE, inside a catch block: rethrows an AgreedRankFailure as it is; any other exception
// is this rank's own failure, which meets the others at their next agreement (so that each of
// them fails too, with the first failing rank's error) and is rethrown as an AgreedRankFailure of
// its status and message (std::bad_alloc: OutOfHostMemory; anything else: Internal).
[[noreturn]] void rethrow_agreed(const RankTransport& ranks);

// The exception being handled (call inside a catch block) as an Error: the C layer's statuses
// for std::bad_alloc (OutOfHostMemory) and anything else (Internal).
Error current_error();

// COLLECTIVE. Runs `body` on every rank and agrees on the outcome: when any rank's body
// throws, every rank throws an AgreedRankFailure.
template <class Body>
void agreed(const RankTransport& ranks, Body&& body) {
  try {
    body();
  } catch (...) {
    rethrow_agreed(ranks);
  }
  agree(ranks);
}

}  // namespace sph
