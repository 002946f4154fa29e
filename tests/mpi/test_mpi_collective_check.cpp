// SPDX-License-Identifier: MIT
// The collective check of MpiTransport (src/mpi/mpi_transport.h, SPH_MPI_CHECK_COLLECTIVES=1),
// under mpirun on 1-4 ranks. Ranks that enter different collectives (a bug in the library's
// rank code: session 21 found one, a rank in an agreement's all_min while the others were in an
// all_max of four floats, which MPI answered with MPI_ERR_TRUNCATE or a hang) must all throw
// Internal, naming the calls, at the same point, and the transport must work on afterwards:
//   - matching calls of every kind give their results with the check on;
//   - a kind mismatch (all_max of float against all_min of int64), a count mismatch (all_sum of
//     2 against 3), and a mismatch inside exchange against gather (both begin with an agreement,
//     which matches; their next calls differ): every rank throws Internal;
//   - session 21's shape: rank 0 fails on its own and joins the others at an agreement
//     (rethrow_agreed, as a step's catch block does) while they are in an all_max of four floats
//     with no agreement before it: every rank throws Internal and none waits. The check's error
//     is an AgreedRankFailure, which rethrow_agreed passes on without meeting the others again: a
//     plain Error would send the others into an agreement that rank 0, already out of its own
//     catch block, never reaches;
//   - the timed barriers (wait_at_barriers) on rank 0 alone: every rank throws Internal at its
//     next call, naming the barrier, instead of rank 0 waiting in MPI_Barrier;
//   - the switch is agreed: set on rank 0 alone it is off on every rank.
// A rank that hung would run the test into ctest's timeout.
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

#include <cstring>
#include <string>

#include "core/rank_agreement.h"
#include "core/status.h"
#include "mpi/mpi_transport.h"

namespace {

int g_rank = 0, g_size = 1, g_failures = 0;

void expect(bool ok, const std::string& what) {
  if (ok) return;
  ++g_failures;
  fprintf(stderr, "rank %d: FAIL: %s\n", g_rank, what.c_str());
}

// Runs `body`, which must throw Internal on this rank with the check's message.
template <class Body>
void expect_mismatch(const char* name, Body&& body) {
  try {
    body();
    expect(false, std::string(name) + ": no error");
  } catch (const sph::Error& e) {
    expect(e.status() == sph::Status::Internal, std::string(name) + ": status is not Internal: " + e.what());
    expect(dynamic_cast<const sph::AgreedRankFailure*>(&e) != nullptr,
           std::string(name) + ": not an AgreedRankFailure (rethrow_agreed would meet the others again)");
    expect(std::strstr(e.what(), "different collectives") != nullptr,
           std::string(name) + ": the message does not name the mismatch: " + e.what());
    if (g_rank == 0) printf("%s: every rank throws Internal; rank 0's message: %s\n", name, e.what());
  }
}

void matching_calls(const sph::MpiTransport& t) {
  int64_t sum[2] = {g_rank + 1, 1};
  t.all_sum(sum, 2);
  expect(sum[0] == int64_t{g_size} * (g_size + 1) / 2 && sum[1] == g_size, "all_sum");
  int64_t lo = g_rank, hi = g_rank;
  t.all_min(&lo, 1);
  t.all_max(&hi, 1);
  expect(lo == 0 && hi == g_size - 1, "all_min / all_max of int64");
  float f[4] = {float(g_rank), 0.5f, -1.0f, 2.0f};
  t.all_max(f, 4);
  expect(f[0] == float(g_size - 1) && f[1] == 0.5f, "all_max of float");
  expect(t.exclusive_sum(g_rank + 1) == int64_t{g_rank} * (g_rank + 1) / 2, "exclusive_sum");
  std::vector<sph::RankBytes> send(static_cast<size_t>(g_size));
  for (int r = 0; r < g_size; ++r)
    send[static_cast<size_t>(r)].assign(static_cast<size_t>(r + 1), (unsigned char)g_rank);
  const std::vector<sph::RankBytes> got = t.exchange(send);
  bool ok = got.size() == static_cast<size_t>(g_size);
  for (int r = 0; ok && r < g_size; ++r)
    ok = got[static_cast<size_t>(r)].size() == static_cast<size_t>(g_rank + 1) &&
         got[static_cast<size_t>(r)][0] == (unsigned char)r;
  expect(ok, "exchange");
  sph::RankBytes mine(static_cast<size_t>(g_rank + 2), (unsigned char)(7 * g_rank));
  const std::vector<sph::RankBytes> all = t.gather(mine, 0);
  expect(g_rank != 0 || (all.size() == static_cast<size_t>(g_size) &&
                         all.back().size() == static_cast<size_t>(g_size + 1)),
         "gather");
  sph::RankBytes text(3, (unsigned char)42);
  const sph::RankBytes b = t.broadcast(g_rank == 0 ? text : sph::RankBytes(), 0);
  expect(b.size() == 3 && b[2] == 42, "broadcast");
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  try {
    setenv("SPH_MPI_CHECK_COLLECTIVES", "1", 1);
    sph::MpiTransport t(MPI_COMM_WORLD);
    expect(t.checks_collectives(), "the check is on with the switch set on every rank");
    matching_calls(t);
    if (g_size > 1) {
      expect_mismatch("all_max of 4 floats on rank 0, all_min of one int64 elsewhere", [&] {
        if (g_rank == 0) {
          float v[4] = {0, 0, 0, 0};
          t.all_max(v, 4);
        } else {
          int64_t v = 0;
          t.all_min(&v, 1);
        }
      });
      expect_mismatch("all_sum of 2 on rank 0, of 3 elsewhere", [&] {
        int64_t v[3] = {0, 0, 0};
        t.all_sum(v, g_rank == 0 ? 2 : 3);
      });
      expect_mismatch("exchange on rank 0, gather elsewhere", [&] {
        if (g_rank == 0)
          t.exchange(std::vector<sph::RankBytes>(static_cast<size_t>(g_size)));
        else
          t.gather(sph::RankBytes(1, 0), 0);
      });
      expect_mismatch("rank 0 fails and joins an agreement, all_max of 4 floats elsewhere", [&] {
        try {
          if (g_rank == 0) throw sph::Error(sph::Status::OutOfHostMemory, "a failure injected on rank 0");
          float v[4] = {0, 0, 0, 0};
          t.all_max(v, 4);  // (the bug: a collective after code that can fail, unagreed)
        } catch (...) {
          sph::rethrow_agreed(t);
        }
      });
      expect_mismatch("timed barriers on rank 0 alone", [&] {
        t.wait_at_barriers(g_rank == 0);
        int64_t v = 0;
        t.all_min(&v, 1);
      });
      t.wait_at_barriers(false);
      // The ranks threw at the same call, so they are in step: the transport works on.
      matching_calls(t);
      t.wait_at_barriers(true);  // and with the barriers on every rank
      matching_calls(t);
      t.wait_at_barriers(false);
    }
    // The switch on rank 0 alone: off everywhere.
    if (g_rank == 0)
      setenv("SPH_MPI_CHECK_COLLECTIVES", "1", 1);
    else
      unsetenv("SPH_MPI_CHECK_COLLECTIVES");
    sph::MpiTransport partial(MPI_COMM_WORLD);
    expect(partial.checks_collectives() == (g_size == 1), "the switch set on rank 0 alone is agreed off");
    matching_calls(partial);
  } catch (const std::exception& e) {
    expect(false, std::string("unexpected exception: ") + e.what());
  }
  int failures = g_failures;
  MPI_Allreduce(MPI_IN_PLACE, &failures, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (g_rank == 0)
    printf("%s collective_check: %d failures over %d ranks\n", failures ? "FAIL" : "PASS", failures, g_size);
  MPI_Finalize();
  return failures ? 1 : 0;
}
