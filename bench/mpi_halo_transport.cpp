// SPDX-License-Identifier: MIT
// mpi_halo_transport.h over the library's internals: the world's backend holds its rank
// transport, and its last report the stages' transport shares. The bench calls these between
// its steps on the thread that steps the world, so no lock is taken.
#include "mpi_halo_transport.h"

#include "capi/handles.h"
#include "mpi/mpi_transport.h"

static_assert(MPI_HALO_CALL_COUNT == sph::kTransportCallCount, "mpi_halo_transport.h's calls");
static_assert(MPI_HALO_PHASE_COUNT == sph::kHaloPhaseCount, "mpi_halo_transport.h's phases");

namespace {

const sph::MpiTransport* transport_of(const sph_world* world) {
  return dynamic_cast<const sph::MpiTransport*>(world->world->backend().rank_transport());
}

}  // namespace

extern "C" int mpi_halo_transport_read(const sph_world* world, mpi_halo_transport* out) {
  const sph::MpiTransport* t = transport_of(world);
  if (!t) return -1;
  const sph::TransportTimes& times = *t->times();
  for (int c = 0; c < sph::kTransportCallCount; ++c) {
    out->calls[c] = times.calls[c];
    out->ms[c] = times.ms[c];
  }
  out->total_ms = times.total_ms;
  const sph::FrameReport& report = world->world->last_report();
  for (int s = 0; s < sph::kStageCount; ++s) {
    out->stage_ms[s] = report.transport_ms[s];
    out->stage_wait_ms[s] = report.transport_wait_ms[s];
  }
  const sph::HaloPhaseTimes* phases = world->world->backend().halo_phase_times();
  for (int p = 0; p < sph::kHaloPhaseCount; ++p) out->phase_ms[p] = phases ? phases->ms[p] : 0.0;
  return 0;
}

extern "C" int mpi_halo_wait_at_barriers(const sph_world* world) {
  const sph::MpiTransport* t = transport_of(world);
  if (!t) return -1;
  t->wait_at_barriers(true);
  return 0;
}

extern "C" const char* mpi_halo_phase_name(int phase) {
  static const char* const kNames[MPI_HALO_PHASE_COUNT] = {"migrate", "ghosts", "springs", "extent",
                                                           "visit",   "grid",   "reorder", "keys"};
  return phase >= 0 && phase < MPI_HALO_PHASE_COUNT ? kNames[phase] : "?";
}

extern "C" const char* mpi_halo_call_name(int call) {
  static const char* const kNames[MPI_HALO_CALL_COUNT] = {"Allreduce", "Exscan",  "Alltoall", "Alltoallv",
                                                          "Gather",    "Gatherv", "Bcast",    "Barrier"};
  return call >= 0 && call < MPI_HALO_CALL_COUNT ? kNames[call] : "?";
}
