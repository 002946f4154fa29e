// SPDX-License-Identifier: MIT
// The transport's times (src/core/rank_transport.h, TransportTimes; issue 19), under mpirun on
// 1-4 ranks, over the library's internals (sph_internal and sph_mpi_objects), as bench/mpi_halo
// reads them:
//   - MpiTransport counts each MPI call it makes by kind (an exchange is its two agreements'
//     Allreduces, an Alltoall and an Alltoallv; with SPH_MPI_CHECK_COLLECTIVES=1, as ctest runs
//     it, one Allreduce more before each call), total_ms is the sum of the kinds' times, and
//     wait_at_barriers puts one timed MPI_Barrier before each call (not before the check's own
//     Allreduce, which must meet a rank without the barriers: the check compares them);
//   - a distributed world's step splits its stages: the hash+sort and density stages hold the
//     halo's exchanges, so their transport time is counted there; no stage's transport share
//     exceeds the stage, nor its barrier waits the share; the barrier waits are zero until
//     wait_at_barriers is on; and an undivided world's report has no transport time.
#include <math.h>
#include <mpi.h>

#include "capi/handles.h"
#include "mpi/mpi_transport.h"
#include "mpi_test_world.h"

namespace {

uint64_t calls_of(const sph::TransportTimes& t) {
  uint64_t n = 0;
  for (int c = 0; c < sph::kTransportCallCount; ++c)
    if (c != sph::kCallBarrier) n += t.calls[c];
  return n;
}

double sum_of(const sph::TransportTimes& t) {
  double ms = 0.0;
  for (int c = 0; c < sph::kTransportCallCount; ++c) ms += t.ms[c];
  return ms;
}

void transport_counts() {
  const sph::MpiTransport t(MPI_COMM_WORLD);
  const int64_t check = t.checks_collectives() ? 1 : 0;  // the check's Allreduce before each call
  const sph::TransportTimes& times = *t.times();
  CHECK(calls_of(times) == 0 && times.total_ms == 0.0, "a new transport has timed calls");
  int64_t v = g_rank;
  t.all_min(&v, 1);
  CHECK(times.calls[sph::kCallAllreduce] == uint64_t(1 + check), "all_min: %llu Allreduces",
        (unsigned long long)times.calls[sph::kCallAllreduce]);
  (void)t.exclusive_sum(1);
  CHECK(times.calls[sph::kCallExscan] == 1, "exclusive_sum: %llu Exscans",
        (unsigned long long)times.calls[sph::kCallExscan]);
  std::vector<sph::RankBytes> send(static_cast<size_t>(g_size), sph::RankBytes(16, 1));
  const uint64_t before = times.calls[sph::kCallAllreduce];
  (void)t.exchange(send);
  // Two agreements (each an all_min, with its check) and the two calls of the exchange's own, each checked.
  CHECK(times.calls[sph::kCallAllreduce] - before == uint64_t(2 * (1 + check) + 2 * check),
        "exchange: %llu Allreduces", (unsigned long long)(times.calls[sph::kCallAllreduce] - before));
  CHECK(times.calls[sph::kCallAlltoall] == 1 && times.calls[sph::kCallAlltoallv] == 1,
        "exchange: %llu Alltoalls, %llu Alltoallvs", (unsigned long long)times.calls[sph::kCallAlltoall],
        (unsigned long long)times.calls[sph::kCallAlltoallv]);
  (void)t.gather(sph::RankBytes(8, 2), 0);
  CHECK(times.calls[sph::kCallGather] == 1 && times.calls[sph::kCallGatherv] == 1, "gather's calls");
  (void)t.broadcast(sph::RankBytes(8, 3), 0);
  CHECK(times.calls[sph::kCallBcast] == 2, "broadcast: %llu Bcasts",
        (unsigned long long)times.calls[sph::kCallBcast]);
  CHECK(times.calls[sph::kCallBarrier] == 0, "barriers while off");
  CHECK(fabs(times.total_ms - sum_of(times)) <= 1e-9 * (1.0 + times.total_ms),
        "total_ms %g, the kinds' sum %g", times.total_ms, sum_of(times));
  for (int c = 0; c < sph::kTransportCallCount; ++c) CHECK(times.ms[c] >= 0.0, "call %d: negative time", c);

  t.wait_at_barriers(true);
  const uint64_t calls = calls_of(times);
  (void)t.exchange(send);
  // (With the check on, every other call is the check's Allreduce, which has no barrier.)
  const uint64_t per_call = t.checks_collectives() ? 2u : 1u;
  CHECK(times.calls[sph::kCallBarrier] * per_call == calls_of(times) - calls,
        "%llu barriers before %llu calls", (unsigned long long)times.calls[sph::kCallBarrier],
        (unsigned long long)(calls_of(times) - calls));
  t.wait_at_barriers(false);
}

const sph::FrameReport& report_of(const sph_world* world) { return world->world->last_report(); }
const sph::TransportTimes* times_of(const sph_world* world) {
  return world->world->backend().rank_transport()->times();
}

void check_split(const sph::FrameReport& r, bool waits, const char* what) {
  for (int s = 0; s < sph::kStageCount; ++s) {
    // (float sums of the same intervals: a stage's share may exceed it by rounding alone)
    CHECK(r.transport_ms[s] >= 0.0f && r.transport_ms[s] <= r.stage_ms[s] * 1.0001f + 1e-4f,
          "%s: stage %d: %g ms in the transport of %g", what, s, (double)r.transport_ms[s],
          (double)r.stage_ms[s]);
    CHECK(r.transport_wait_ms[s] >= 0.0f && r.transport_wait_ms[s] <= r.transport_ms[s] * 1.0001f + 1e-4f,
          "%s: stage %d: %g ms of barrier waits of %g", what, s, (double)r.transport_wait_ms[s],
          (double)r.transport_ms[s]);
    if (!waits) CHECK(r.transport_wait_ms[s] == 0.0f, "%s: stage %d: barrier waits while off", what, s);
  }
  if (g_size > 1) {
    CHECK(r.transport_ms[sph::kStageHashSort] > 0.0f, "%s: no transport time in hash+sort", what);
    CHECK(r.transport_ms[sph::kStageDensity] > 0.0f, "%s: no transport time in density", what);
  }
}

void world_split(sph_context* context) {
  sph_world_def def;
  sph_world* single = nullptr;
  sph_world* world = nullptr;
  uint32_t n = 0;
  sph_stats stats;
  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 0.0f, nullptr, &single, &world, &n);
  const sph::TransportTimes* times = times_of(world);
  REQUIRE(times != nullptr, "a distributed world's transport does not time its calls");
  const uint64_t before = calls_of(*times);
  mpi_test_step_stats(world, 3, 1, &stats);
  CHECK(calls_of(*times) > before, "a step made no timed call");
  check_split(report_of(world), false, "step");
  if (single) {
    mpi_test_step_stats(single, 3, 0, &stats);
    for (int s = 0; s < sph::kStageCount; ++s)
      CHECK(report_of(single).transport_ms[s] == 0.0f, "undivided: stage %d has transport time", s);
  }
  const auto* transport = dynamic_cast<const sph::MpiTransport*>(world->world->backend().rank_transport());
  transport->wait_at_barriers(true);
  const uint64_t barriers = times->calls[sph::kCallBarrier];
  const uint64_t calls = calls_of(*times);
  mpi_test_step_stats(world, 3, 1, &stats);
  const uint64_t per_call = transport->checks_collectives() ? 2u : 1u;  // (the check's Allreduces)
  CHECK((times->calls[sph::kCallBarrier] - barriers) * per_call == calls_of(*times) - calls,
        "a call without its barrier");
  check_split(report_of(world), true, "step with barriers");
  if (single) sph_world_destroy(single);
  sph_world_destroy(world);
}

}  // namespace

int main(int argc, char** argv) {
  sph_context* context = nullptr;
  mpi_test_init(&argc, &argv, &context);
  transport_counts();
  world_split(context);
  return mpi_test_finish(context, "mpi_transport_times");
}
