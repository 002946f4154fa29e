// SPDX-License-Identifier: MIT
#include "mpi_transport.h"

#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <string>

#include "../core/rank_agreement.h"
#include "../core/status.h"

namespace sph {

namespace {

std::string mpi_error_text(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  return std::string(text, static_cast<size_t>(length));
}

void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  throw Error(Status::Internal, std::string("MPI: ") + what + " failed: " + mpi_error_text(code));
}

// The signature one rank contributes: kind in bits 32-39, the detail in the low half, and bit 40
// set where the rank puts a timed barrier before its calls (wait_at_barriers): a rank with the
// barriers and one without would meet in MPI_Barrier against another collective.
constexpr int64_t kBarrierBit = int64_t{1} << 40;
int64_t signature(Collective kind, int64_t detail, bool barrier) {
  return static_cast<int64_t>(kind) * (int64_t{1} << 32) + (detail & 0xffffffffll) +
         (barrier ? kBarrierBit : 0);
}

const char* collective_name(Collective kind) {
  switch (kind) {
    case Collective::AllMinInt64:
      return "all_min of int64";
    case Collective::AllMaxInt64:
      return "all_max of int64";
    case Collective::AllSumInt64:
      return "all_sum of int64";
    case Collective::AllMaxFloat:
      return "all_max of float";
    case Collective::ExclusiveSum:
      return "exclusive_sum";
    case Collective::Alltoall:
      return "exchange's MPI_Alltoall";
    case Collective::Alltoallv:
      return "exchange's MPI_Alltoallv";
    case Collective::Gather:
      return "gather's MPI_Gather to root";
    case Collective::Gatherv:
      return "gather's MPI_Gatherv to root";
    case Collective::BroadcastSize:
      return "broadcast's size from root";
    case Collective::BroadcastBytes:
      return "broadcast's bytes from root";
  }
  return "an unknown collective";
}

std::string describe(int64_t sig) {
  const auto kind = static_cast<Collective>((sig >> 32) & 0xff);
  return std::string(collective_name(kind)) + " (" + std::to_string(sig & 0xffffffffll) + ")" +
         ((sig & kBarrierBit) ? " after a timed barrier" : "");
}

int as_count(size_t n) {
  if (n > static_cast<size_t>(INT_MAX)) throw Error(Status::Capacity, "MPI: a message of more than 2 GiB");
  return static_cast<int>(n);
}

}  // namespace

MpiTransport::MpiTransport(MPI_Comm comm) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized)
    throw Error(Status::InvalidArgument, "comm: MPI is not initialised (call MPI_Init first)");
  if (comm == MPI_COMM_NULL) throw Error(Status::InvalidArgument, "comm: is MPI_COMM_NULL");
  // A handle that names no communicator (a stray integer, a freed one) cannot report its error on
  // itself: MPI raises it on MPI_COMM_WORLD, whose handler aborts the job unless the caller chose
  // otherwise. So the duplication runs with that handler set to return, and the caller's is put
  // back before anything else (MPI gives no other way to ask whether a handle is valid).
  MPI_Errhandler caller_handler = MPI_ERRHANDLER_NULL;
  MPI_Comm_get_errhandler(MPI_COMM_WORLD, &caller_handler);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  const int duplicated = MPI_Comm_dup(comm, &comm_);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, caller_handler);
  MPI_Errhandler_free(&caller_handler);
  if (duplicated != MPI_SUCCESS)
    throw Error(Status::InvalidArgument,
                "comm: MPI refused to duplicate it (" + mpi_error_text(duplicated) +
                    "): pass MPI_Comm_c2f of a valid communicator, the same on every rank");
  // Errors come back as codes (check() turns them into Errors), not as an abort.
  MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN);
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  // The switch is agreed (a rank without it turns it off everywhere): ranks that disagreed about
  // checking would meet a check's all-reduce against another rank's collective.
  const char* env = std::getenv("SPH_MPI_CHECK_COLLECTIVES");
  int on = env && std::strcmp(env, "1") == 0 ? 1 : 0;
  const int agreed = MPI_Allreduce(MPI_IN_PLACE, &on, 1, MPI_INT, MPI_MIN, comm_);
  if (agreed != MPI_SUCCESS) MPI_Comm_free(&comm_);  // no destructor runs after a throw here
  check(agreed, "MPI_Allreduce (the collective check's switch)");
  check_collectives_ = on != 0;
}

template <class Call>
int MpiTransport::timed(TransportCall call, Call&& mpi, bool barrier) const {
  using Clock = std::chrono::steady_clock;
  auto add = [this](TransportCall c, Clock::time_point since) {
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - since).count();
    times_.calls[c] += 1;
    times_.ms[c] += ms;
    times_.total_ms += ms;
  };
  if (barrier && wait_at_barriers_) {
    const auto t = Clock::now();
    check(MPI_Barrier(comm_), "MPI_Barrier (the timed wait before a call)");
    add(kCallBarrier, t);
  }
  const auto t = Clock::now();
  const int code = mpi();
  add(call, t);
  return code;
}

void MpiTransport::match(Collective kind, int64_t detail) const {
  if (!check_collectives_) return;
  const int64_t mine = signature(kind, detail, wait_at_barriers_);
  int64_t range[2] = {mine, -mine};  // the largest signature and minus the smallest
  // (Never after a barrier of its own: the check must meet a rank without the barriers.)
  check(timed(
            kCallAllreduce,
            [&] { return MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_INT64_T, MPI_MAX, comm_); }, false),
        "MPI_Allreduce (collective check)");
  if (range[0] == -range[1]) return;
  // Every rank knows of this failure already: an AgreedRankFailure, which rethrow_agreed passes
  // on as it is. A plain Error would send a rank whose collective sat inside a step's try block
  // into an agreement that a rank thrown out of its own catch block (rethrow_agreed's all_min
  // against the others' collective, session 21's shape) never reaches.
  throw AgreedRankFailure(Status::Internal,
                          "MPI collective check (SPH_MPI_CHECK_COLLECTIVES=1): the ranks were in "
                          "different collectives: rank " +
                              std::to_string(rank_) + " in " + describe(mine) +
                              "; the ranks' calls range from " + describe(-range[1]) + " to " +
                              describe(range[0]));
}

MpiTransport::~MpiTransport() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized && comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

void MpiTransport::all_min(int64_t* values, int n) const {
  match(Collective::AllMinInt64, n);
  check(timed(kCallAllreduce,
              [&] { return MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_MIN, comm_); }),
        "MPI_Allreduce");
}
void MpiTransport::all_max(int64_t* values, int n) const {
  match(Collective::AllMaxInt64, n);
  check(timed(kCallAllreduce,
              [&] { return MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_MAX, comm_); }),
        "MPI_Allreduce");
}
void MpiTransport::all_sum(int64_t* values, int n) const {
  match(Collective::AllSumInt64, n);
  check(timed(kCallAllreduce,
              [&] { return MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_INT64_T, MPI_SUM, comm_); }),
        "MPI_Allreduce");
}
void MpiTransport::all_max(float* values, int n) const {
  match(Collective::AllMaxFloat, n);
  check(timed(kCallAllreduce,
              [&] { return MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_FLOAT, MPI_MAX, comm_); }),
        "MPI_Allreduce");
}

int64_t MpiTransport::exclusive_sum(int64_t value) const {
  int64_t below = 0;
  match(Collective::ExclusiveSum, 1);
  check(timed(kCallExscan, [&] { return MPI_Exscan(&value, &below, 1, MPI_INT64_T, MPI_SUM, comm_); }),
        "MPI_Exscan");
  return rank_ == 0 ? 0 : below;  // (MPI leaves rank 0's result undefined)
}

// The buffers are made between agreements (core/rank_agreement.h): a rank whose allocation
// fails meets the others at the next one, before they enter the MPI call it would miss.
std::vector<RankBytes> MpiTransport::exchange(const std::vector<RankBytes>& send) const {
  const size_t n = static_cast<size_t>(size_);
  if (send.size() != n) throw Error(Status::Internal, "exchange: one buffer per rank");
  std::vector<int> send_counts, recv_counts, send_offsets, recv_offsets;
  RankBytes packed, in;
  try {
    send_counts.resize(n);
    recv_counts.resize(n);
    send_offsets.resize(n);
    recv_offsets.resize(n);
    size_t total = 0;
    for (size_t r = 0; r < n; ++r) {
      send_counts[r] = as_count(send[r].size());
      send_offsets[r] = as_count(total);
      total += send[r].size();
    }
    packed.reserve(total);
    for (const RankBytes& b : send) packed.insert(packed.end(), b.begin(), b.end());
  } catch (...) {
    rethrow_agreed(*this);
  }
  agree(*this);
  match(Collective::Alltoall, 1);
  check(timed(kCallAlltoall,
              [&] {
                return MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm_);
              }),
        "MPI_Alltoall");
  try {
    size_t received = 0;
    for (size_t r = 0; r < n; ++r) {
      recv_offsets[r] = as_count(received);
      received += static_cast<size_t>(recv_counts[r]);
    }
    in.resize(received);
  } catch (...) {
    rethrow_agreed(*this);
  }
  agree(*this);
  match(Collective::Alltoallv, 0);
  check(timed(kCallAlltoallv,
              [&] {
                return MPI_Alltoallv(packed.data(), send_counts.data(), send_offsets.data(), MPI_BYTE,
                                     in.data(), recv_counts.data(), recv_offsets.data(), MPI_BYTE, comm_);
              }),
        "MPI_Alltoallv");
  // (A failure from here on is met by the caller's next agreement.)
  std::vector<RankBytes> out(n);
  for (size_t r = 0; r < n; ++r)
    out[r].assign(in.begin() + recv_offsets[r], in.begin() + recv_offsets[r] + recv_counts[r]);
  return out;
}

std::vector<RankBytes> MpiTransport::gather(const RankBytes& mine, int root) const {
  const size_t n = static_cast<size_t>(size_);
  int count = 0;
  std::vector<int> counts, offsets;
  RankBytes all;
  try {
    count = as_count(mine.size());
    counts.resize(rank_ == root ? n : 0);
    offsets.resize(rank_ == root ? n : 0);
  } catch (...) {
    rethrow_agreed(*this);
  }
  agree(*this);
  match(Collective::Gather, root);
  check(timed(kCallGather,
              [&] { return MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm_); }),
        "MPI_Gather");
  try {
    size_t total = 0;
    if (rank_ == root)
      for (size_t r = 0; r < n; ++r) {
        offsets[r] = as_count(total);
        total += static_cast<size_t>(counts[r]);
      }
    all.resize(total);
  } catch (...) {
    rethrow_agreed(*this);
  }
  agree(*this);
  match(Collective::Gatherv, root);
  check(timed(kCallGatherv,
              [&] {
                return MPI_Gatherv(mine.data(), count, MPI_BYTE, all.data(), counts.data(), offsets.data(),
                                   MPI_BYTE, root, comm_);
              }),
        "MPI_Gatherv");
  std::vector<RankBytes> out;
  if (rank_ == root) {
    out.resize(n);
    for (size_t r = 0; r < n; ++r)
      out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
  }
  return out;
}

RankBytes MpiTransport::broadcast(const RankBytes& bytes, int root) const {
  uint64_t size = bytes.size();
  match(Collective::BroadcastSize, root);
  check(timed(kCallBcast, [&] { return MPI_Bcast(&size, 1, MPI_UINT64_T, root, comm_); }), "MPI_Bcast");
  RankBytes out(rank_ == root ? bytes : RankBytes(static_cast<size_t>(size)));
  match(Collective::BroadcastBytes, root);
  const int count = as_count(out.size());
  check(timed(kCallBcast, [&] { return MPI_Bcast(out.data(), count, MPI_BYTE, root, comm_); }), "MPI_Bcast");
  return out;
}

}  // namespace sph
